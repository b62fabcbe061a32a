"""Adjust the installed ``slicer-core-sdk`` wheel so that CMake can build against it here.

Each change was found by a failing configure or load (see Docs/BuildModes.md):

* ITK's ``ITKVtkGlue.cmake`` sets ``VTK_DIR`` to a path on the machine that built the
  wheel, which breaks every later ``find_package(VTK)``;
* the package config walks component dependencies and queries ``Slicer::VTK::...``
  targets for names that belong to other packages;
* the Python module properties name the package ``slicer_core_sdk``, while at run time
  the wrapped modules live in ``slicer_core``;
* the imported libraries point at the SDK's copies, whose dependencies only resolve
  next to the ``slicer_core`` wheel's own copies: link against those instead.

The edits are idempotent and recorded in a stamp file inside the wheel's folder.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

PATCH_VERSION = 2


def _edit(path: Path, transform) -> None:
    text = path.read_text()
    new_text = transform(text)
    if new_text != text:
        path.write_text(new_text)


def patch(site_packages: Path) -> Path:
    sdk = site_packages / "slicer_core_sdk" / "content"
    stamp = sdk / f".volumecutting-patched-v{PATCH_VERSION}"
    cmake_dir = sdk / "cmake" / "slicer_core_sdk"
    if stamp.exists():
        return cmake_dir
    if not cmake_dir.is_dir():
        raise RuntimeError(f"slicer-core-sdk is not installed in {site_packages}")

    _edit(sdk / "third_party" / "lib" / "cmake" / "ITK-5.4" / "Modules" / "ITKVtkGlue.cmake",
          lambda text: re.sub(r'^set\(VTK_DIR "[^"]*"\)\n', "", text, flags=re.M))

    def skip_foreign_components(text: str) -> str:
        marker = "  foreach(dependency IN LISTS dependencies)\n"
        guard = marker + "    if(dependency MATCHES \"::\")\n      continue()\n    endif()\n"
        return text if guard in text else text.replace(marker, guard)
    _edit(cmake_dir / "slicer_core_sdk-config.cmake", skip_foreign_components)

    _edit(cmake_dir / "slicer_core_sdk-vtk-python-module-properties.cmake",
          lambda text: text.replace('"INTERFACE_vtk_module_python_package" "slicer_core_sdk"',
                                    '"INTERFACE_vtk_module_python_package" "slicer_core"'))

    _edit(cmake_dir / "slicer_core_sdk-targets-release.cmake",
          lambda text: text.replace("${_IMPORT_PREFIX}/slicer_core_sdk/content/lib/",
                                    "${_IMPORT_PREFIX}/slicer_core/"))
    stamp.write_text("patched by Utilities/Setup/slicer_sdk.py\n")
    return cmake_dir


if __name__ == "__main__":
    print(patch(Path(sys.argv[1])))
