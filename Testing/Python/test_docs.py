"""The documentation matches the code: README's shape, names in Docs/, and the architecture diagram.

A newcomer reads README.md and Docs/ first; a class, module or path named there that does not exist (renamed,
moved, split) sends them the wrong way. These tests read the repository's source tree, not the installed wheel.
"""

import html
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
DOCS = sorted((REPO / "Docs").glob("*.md")) + [REPO / "README.md"]
DIAGRAM_SOURCE = REPO / "Docs" / "architecture.dot"
DIAGRAM = REPO / "Docs" / "architecture.svg"

# Classes of VTK, Slicer and Qt that the documents name beside the project's own.
# A name followed by * is a prefix (`vtkMRML*`), one ending in Macro(s) a macro.
CLASS_NAME = re.compile(r"\b((?:vtk|qSlicer|qMRML)[A-Z][A-Za-z0-9]+)\b(?![*])")
# Placeholders the developers' guide uses in its recipes.
EXAMPLE_NAMES = {"vtkMyClass"}
PYTHON_NAME = re.compile(r"\bVolumeCuttingLib(?:\.[A-Za-z_][A-Za-z0-9_]*)*")
PATH_NAME = re.compile(r"`((?:Modules|VolumeCutting|VolumeCuttingLib|Docs|Utilities|Resources|Testing|CMake|benchmarks)/[^`\s*<>]+)`")
LIBRARY_PARENT = REPO / "Modules" / "Scripted" / "VolumeCuttingTools"


def _text(path):
    return path.read_text(encoding="utf-8")


def _project_classes():
    # Test drivers (vtkVolumeCutFieldTest1.cxx) and shader sources (vtkVolumeCutRayCastFS.glsl) are named like
    # classes, and the documents name them too.
    sources = [p for suffix in ("*.h", "*.cxx", "*.glsl") for p in REPO.rglob(suffix)]
    return {p.stem for p in sources if ".venv" not in p.parts and "build" not in p.parts}


def _sdk_headers():
    """Header names of the VTK and Slicer SDKs this checkout builds against (internal classes are not wrapped)."""
    import slicer_core_sdk

    folders = [Path(slicer_core_sdk.__file__).parent / "content"]
    platform = REPO / "build" / "platform.cmake"
    if platform.exists():
        vtk_dir = re.search(r'set\(VTK_DIR "([^"]+)"', platform.read_text())
        if vtk_dir:
            folders.append(Path(vtk_dir.group(1)).parents[3] / "include")
    return {header.stem for folder in folders if folder.exists() for header in folder.rglob("vtk*.h")}


def _external_class_exists(name, headers):
    import slicer
    import vtk

    return hasattr(vtk, name) or hasattr(slicer, name) or name in headers


def _is_macro(name):
    return name.endswith("Macro") or name.endswith("Macros")


def test_readme_starts_with_the_two_commands_and_reads_in_two_minutes():
    lines = _text(REPO / "README.md").splitlines()
    assert len(lines) <= 200, f"README.md has {len(lines)} lines; figures belong in Docs/Status.md"
    first_block = lines[lines.index("```") + 1 : lines.index("```", lines.index("```") + 1)]
    assert [line.split()[:2] for line in first_block] == [["Utilities/vc", "main"], ["Utilities/vc", "test"]]
    ci = _text(REPO / ".ci" / "run")
    assert "Utilities/vc test" in ci


def test_every_status_row_is_one_short_line():
    readme = _text(REPO / "README.md")
    table = readme[readme.index("## Status") : readme.index("## Layout")]
    rows = [line for line in table.splitlines() if line.startswith("| ") and not line.startswith("| part")]
    assert rows, "README has no status table"
    for row in rows:
        state = row.strip("|").split(" | ")[1]
        assert len(state) <= 120, f"status cell holds a paragraph: {row[:80]}..."


@pytest.mark.parametrize("document", DOCS, ids=lambda p: p.name)
def test_every_class_named_in_the_docs_exists(document):
    own, headers = _project_classes(), _sdk_headers()
    missing = sorted(
        name for name in set(CLASS_NAME.findall(_text(document)))
        if name not in own and name not in EXAMPLE_NAMES and not _is_macro(name) and not _external_class_exists(name, headers)
    )
    assert not missing, f"{document.name} names classes that exist neither here nor in VTK/Slicer: {missing}"


@pytest.mark.parametrize("document", DOCS, ids=lambda p: p.name)
def test_every_python_module_named_in_the_docs_exists(document):
    library_root = LIBRARY_PARENT
    missing = []
    for dotted in set(PYTHON_NAME.findall(_text(document))):
        parts = dotted.split(".")
        # The longest prefix that is a module must exist; what follows it must be defined in it.
        for cut in range(len(parts), 0, -1):
            candidate = library_root.joinpath(*parts[:cut])
            module_file = candidate.with_suffix(".py")
            if (candidate / "__init__.py").exists() or module_file.exists():
                break
        else:
            missing.append(dotted)
            continue
        rest = parts[cut:]
        if rest:
            source = _text(module_file if module_file.exists() else candidate / "__init__.py")
            if not re.search(rf"^(?:def|class|async def)\s+{re.escape(rest[0])}\b|^{re.escape(rest[0])}\s*[:=]", source, re.M):
                missing.append(dotted)
    assert not missing, f"{document.name} names Python modules or attributes that do not exist: {sorted(missing)}"


@pytest.mark.parametrize("document", DOCS, ids=lambda p: p.name)
def test_every_repository_path_named_in_the_docs_exists(document):
    def exists(path):
        root = LIBRARY_PARENT if path.startswith("VolumeCuttingLib/") else REPO
        return (root / path.rstrip("/")).exists()

    missing = sorted({path for path in PATH_NAME.findall(_text(document)) if not exists(path)})
    assert not missing, f"{document.name} names paths that do not exist: {missing}"


def _diagram_labels(dot_source):
    labels = set()
    for label in re.findall(r'label="((?:[^"\\]|\\.)*)"', dot_source):
        labels.update(line.strip() for line in label.split("\\n") if line.strip())
    return labels


def test_architecture_opens_with_the_diagram_made_from_its_source():
    architecture = _text(REPO / "Docs" / "Architecture.md")
    first_section = architecture.split("\n## ", 1)[0]
    assert "architecture.svg" in first_section, "Architecture.md must open with the diagram"
    svg_text = {html.unescape(text).strip() for text in re.findall(r"<text[^>]*>([^<]*)</text>", _text(DIAGRAM))}
    expected = _diagram_labels(_text(DIAGRAM_SOURCE))
    assert expected - svg_text == set() and svg_text - expected == set(), (
        "Docs/architecture.svg was not made from Docs/architecture.dot: run "
        "`dot -Tsvg Docs/architecture.dot -o Docs/architecture.svg`"
    )


def test_every_name_in_the_diagram_exists():
    dot = _text(DIAGRAM_SOURCE)
    own = _project_classes()
    for name in set(CLASS_NAME.findall(dot)):
        assert name in own, f"architecture.dot names {name}, which is not a class of this repository"
    folders = {"VolumeCuttingCore", "VolumeCuttingRendering", "VolumeCuttingSoftCut"}
    for folder in folders:
        assert (REPO / "Modules" / "VTK" / folder).is_dir()
    for package in ("webapp", "jobs", "config", "cutting", "data", "scene"):
        assert package in dot
        assert (REPO / "Modules" / "Scripted" / "VolumeCuttingTools" / "VolumeCuttingLib" / package / "__init__.py").exists()


def test_the_name_checks_can_fail():
    """The patterns find what a stale document would hold."""
    stale = "`vtkVolumeCutNoSuchThing` in `Modules/VTK/NoSuchFolder/` via VolumeCuttingLib.nosuchmodule"
    assert CLASS_NAME.findall(stale) == ["vtkVolumeCutNoSuchThing"]
    assert PATH_NAME.findall(stale) == ["Modules/VTK/NoSuchFolder/"]
    assert PYTHON_NAME.findall(stale) == ["VolumeCuttingLib.nosuchmodule"]
    assert "vtkVolumeCutNoSuchThing" not in _project_classes()
