"""Remove the files of an installed Python package that the last CMake install did not write.

Utilities/vc's incremental build copies changed files into site-packages with ``cmake --install``,
which never deletes: a module moved or removed in the source tree would stay importable from
site-packages and hide the change from the tests. This keeps the installed package equal to what
the build installs.

    python prune_install.py build/core/install_manifest.txt SITE_PACKAGES/VolumeCuttingLib
"""

import sys
from pathlib import Path


def prune(manifest: Path, package: Path) -> list[Path]:
    installed = {Path(line.strip()).resolve() for line in manifest.read_text().splitlines() if line.strip()}
    removed = []
    for path in sorted(package.rglob("*"), reverse=True):
        if path.is_file() and "__pycache__" not in path.parts and path.resolve() not in installed:
            path.unlink()
            removed.append(path)
    for path in sorted(package.rglob("__pycache__"), reverse=True):
        # Bytecode of a module that is gone would still import.
        for compiled in path.glob("*.pyc"):
            source = path.parent / (compiled.name.split(".")[0] + ".py")
            if not source.exists():
                compiled.unlink()
    for path in sorted(package.rglob("*"), reverse=True):
        if path.is_dir() and not any(path.iterdir()):
            path.rmdir()
    return removed


if __name__ == "__main__":
    for path in prune(Path(sys.argv[1]), Path(sys.argv[2])):
        print(f"[build] removed {path}: no longer installed by the build")
