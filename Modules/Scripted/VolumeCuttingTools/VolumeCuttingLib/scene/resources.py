"""Where the files shipped with VolumeCutting (presets, recorded sessions) are, however it is installed."""

from __future__ import annotations

from pathlib import Path


def find_resource(*relative: str) -> Path:
    """A file under ``Resources/``: in the wheel (inside VolumeCuttingLib), in
    desktop Slicer (the scripted module's Resources beside VolumeCuttingLib) or
    in the source tree (top-level Resources). Raises FileNotFoundError naming
    the places tried.
    """
    library = Path(__file__).resolve().parents[1]
    roots = [library / "Resources", library.parent / "Resources"]
    if len(library.parents) > 3:
        roots.append(library.parents[3] / "Resources")
    candidates = [root.joinpath(*relative) for root in roots]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    tried = ", ".join(str(candidate) for candidate in candidates)
    raise FileNotFoundError(f"{'/'.join(relative)} was not found (looked in {tried}); reinstall VolumeCutting")
