"""The shape of the code: no import circles in VolumeCuttingLib, no overlong source file.

An import circle lets a module run with a half-initialised neighbour and ties
layers that should stack (scene, data, config, cutting, feedback, assessment, collaboration, jobs, records,
webapp, benchmarks) into one knot. Every ``import`` and ``from ... import`` counts,
inside functions too: a late import hides the circle from Python but not from
the reader. The graph is read with ``ast``, so nothing is imported and the
check needs neither VTK nor Slicer.
"""

import ast
import importlib.util
import os
import subprocess
import sysconfig
from pathlib import Path

import pytest

PACKAGE = "VolumeCuttingLib"
# Modules/Scripted/VolumeCuttingTools/Testing/Python/<this file>: the repository root is five levels up.
REPOSITORY = Path(__file__).resolve().parents[5]
SOURCE_SUFFIXES = (".py", ".cxx", ".h", ".glsl", ".js")
MAX_LINES = 1500
# The subpackages from the bottom up: each may import its own layer and those before it, never one after.
LAYERS = ("scene", "data", "config", "cutting", "feedback", "assessment", "collaboration", "jobs", "records", "webapp", "benchmarks")


def package_modules(root: Path, package: str = PACKAGE) -> dict:
    """Module name -> (file, whether it is a package's ``__init__``) for every module under ``root``."""
    modules = {}
    for path in sorted(root.rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        is_package = parts[-1] == "__init__"
        if is_package:
            parts.pop()
        modules[".".join([package, *parts])] = (path, is_package)
    return modules


def imported_modules(tree: ast.AST, name: str, is_package: bool, known) -> set:
    """The modules of ``known`` that the module ``name`` imports anywhere in its body."""
    own_package = name if is_package else name.rpartition(".")[0]
    found = set()

    def most_specific(dotted: str):
        # ``import a.b.c`` where ``a.b.c`` is no module of ours (a function, a class) means its longest module prefix.
        while dotted and dotted not in known:
            dotted = dotted.rpartition(".")[0]
        return dotted or None

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            targets = [most_specific(alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base_parts = own_package.split(".")
                base_parts = base_parts[:len(base_parts) - (node.level - 1)]
                base = ".".join(base_parts + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            # ``from base import x`` imports the submodule base.x where there is one, else takes x from base.
            targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in known else most_specific(base)
                       for alias in node.names]
        else:
            continue
        found.update(target for target in targets if target is not None and target != name)
    return found


def import_graph(root: Path, package: str = PACKAGE) -> dict:
    """Module name -> the package's modules it imports."""
    modules = package_modules(root, package)
    return {name: imported_modules(ast.parse(path.read_text(), str(path)), name, is_package, modules)
            for name, (path, is_package) in modules.items()}


def find_cycle(graph: dict):
    """One import circle of ``graph`` as a list of nodes that starts and ends with the same one, or None."""
    state = {}  # node -> "open" while on the depth-first path, "done" once all it reaches is explored
    for start in sorted(graph):
        if start in state:
            continue
        path = [start]
        children = [iter(sorted(graph.get(start, ())))]
        state[start] = "open"
        while path:
            child = next(children[-1], None)
            if child is None:
                state[path.pop()] = "done"
                children.pop()
            elif state.get(child) == "open":
                return path[path.index(child):] + [child]
            elif child not in state:
                state[child] = "open"
                path.append(child)
                children.append(iter(sorted(graph.get(child, ()))))
    return None


def installed_package_roots() -> list:
    """The VolumeCuttingLib that Python imports and, where it differs, the one installed in site-packages."""
    roots = []
    spec = importlib.util.find_spec(PACKAGE)
    if spec is not None and spec.submodule_search_locations:
        roots.extend(Path(location).resolve() for location in spec.submodule_search_locations)
    for scheme in ("platlib", "purelib"):
        candidate = Path(sysconfig.get_paths()[scheme]) / PACKAGE
        if (candidate / "__init__.py").is_file() and candidate.resolve() not in roots:
            roots.append(candidate.resolve())
    return roots


def test_find_cycle_names_a_circle_and_passes_a_layered_graph():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"top": {"middle", "bottom"}, "middle": {"bottom"}, "bottom": set()}) is None
    assert find_cycle({"x": {"x"}}) == ["x", "x"]
    # The circle sits behind an acyclic branch explored first.
    assert find_cycle({"a": {"b", "c"}, "b": set(), "c": {"d"}, "d": {"c"}}) == ["c", "d", "c"]


def test_import_graph_sees_relative_absolute_and_late_imports(tmp_path):
    """A tiny package whose circle closes only through an import inside a function is caught."""
    root = tmp_path / "toy"
    (root / "low").mkdir(parents=True)
    (root / "high").mkdir()
    (root / "__init__.py").write_text("")
    (root / "low" / "__init__.py").write_text("")
    (root / "high" / "__init__.py").write_text("")
    (root / "low" / "base.py").write_text("def later():\n    from ..high.job import run\n    return run\n")
    (root / "high" / "job.py").write_text("from ..low import base\nimport toy.low.base\n\ndef run():\n    pass\n")
    (root / "high" / "other.py").write_text("from toy.high import job\nfrom . import job as again\n")
    graph = import_graph(root, "toy")
    assert graph["toy.low.base"] == {"toy.high.job"}
    assert graph["toy.high.job"] == {"toy.low.base"}
    assert graph["toy.high.other"] == {"toy.high.job"}
    assert find_cycle(graph) in (["toy.high.job", "toy.low.base", "toy.high.job"],
                                 ["toy.low.base", "toy.high.job", "toy.low.base"])


@pytest.mark.parametrize("root", installed_package_roots(), ids=str)
def test_volume_cutting_lib_has_no_import_circle(root):
    graph = import_graph(root)
    edges = sum(len(targets) for targets in graph.values())
    assert len(graph) > 30 and edges > 50, f"{root}: {len(graph)} modules, {edges} imports: the check would prove nothing"
    cycle = find_cycle(graph)
    assert cycle is None, f"import circle in {root}: " + " -> ".join(cycle)


@pytest.mark.parametrize("root", installed_package_roots(), ids=str)
def test_subpackages_import_only_their_layer_and_those_below(root):
    graph = import_graph(root)

    def layer(module):
        parts = module.split(".")
        return LAYERS.index(parts[1]) if len(parts) > 1 and parts[1] in LAYERS else None

    unknown = sorted(module for module in graph if module != PACKAGE and layer(module) is None)
    assert not unknown, f"modules outside the subpackages {LAYERS}: {unknown}"
    upward = sorted(f"{module} -> {target}" for module, targets in graph.items() if module != PACKAGE
                    for target in targets if target != PACKAGE and layer(target) > layer(module))
    assert not upward, "imports of a higher layer: " + ", ".join(upward)


def test_the_library_is_found():
    assert installed_package_roots(), f"{PACKAGE} is neither importable nor installed"


def tracked_source_files() -> list:
    """The product's source files: tracked by git where the tree is a checkout, else every one under the root."""
    try:
        listed = subprocess.run(["git", "-C", str(REPOSITORY), "ls-files", "-z", *(f"*{s}" for s in SOURCE_SUFFIXES)],
                                capture_output=True, check=True, text=True).stdout.split("\0")
        return [REPOSITORY / name for name in listed if name]
    except (OSError, subprocess.CalledProcessError):
        pass  # no git, or a source tree that is not a checkout (an unpacked sdist)
    files = []
    for folder, subfolders, names in os.walk(REPOSITORY):
        # Build trees, virtual environments and hidden folders hold no product source.
        subfolders[:] = [name for name in subfolders if name not in ("build", "__pycache__") and not name.startswith(".")]
        files.extend(Path(folder) / name for name in names if name.endswith(SOURCE_SUFFIXES))
    return files


def test_no_source_file_is_longer_than_the_limit():
    files = tracked_source_files()
    assert len(files) > 100, f"{len(files)} source files under {REPOSITORY}: the check would prove nothing"
    too_long = {}
    for path in files:
        if path.is_file():
            with open(path, "rb") as stream:
                lines = sum(1 for _ in stream)
            if lines > MAX_LINES:
                too_long[str(path.relative_to(REPOSITORY))] = lines
    assert not too_long, f"source files longer than {MAX_LINES} lines (split them by responsibility): " + \
        ", ".join(f"{name} ({lines})" for name, lines in sorted(too_long.items()))
