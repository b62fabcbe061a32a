"""Assemble a VTK 9.6.2 SDK that matches the ``vtk==9.6.2`` wheel.

The wheel ships VTK's libraries but no headers and no CMake package, and Kitware's
``vtk-sdk`` wheel exists for macOS only.  Debian sid packages VTK 9.6.2 from the same
sources, so its headers, CMake package, hierarchy files and wrap tools are taken from
there and re-pointed at the wheel's libraries:

* library targets locate the wheel's ``libvtkX.so`` under ``VTK_WHEEL_LIBRARY_DIR``
  (a CMake variable, so one SDK serves any virtual environment);
* link interfaces keep only VTK, Threads and Python targets: the wheel carries its own
  third-party code, so Debian's external packages must not be searched for;
* ``vtkSMP.h`` describes the wheel's SMP back ends (Sequential and STDThread), not
  Debian's TBB build, otherwise ``vtkSMPToolsAPI`` has another layout than the library;
* the wrap tools need glibc 2.38 or newer: they run through sid's own loader.

Everything is pinned by version and SHA-256 and cached outside the repository.
"""

from __future__ import annotations

import hashlib
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

SID_PACKAGES = {
    # name: (version, sha256)
    "libvtk9-dev": ("9.6.2+ds-4", "9e630ee05edf5e5be1404d1e236e340c533afe5815136303f0d68d7350bfa8ef"),
    "libvtk9.6": ("9.6.2+ds-4", "2416a1bcedc44efb98d405221b37b85d1b518bd16c9b06771f64c2e9cb1b279f"),
    "vtk9": ("9.6.2+ds-4", "8fc9cde6039b0994a7e1f0f6e0d1a96f61b5927b27273ff3dcb2aa8d77ecb3c3"),
    "python3-vtk9": ("9.6.2+ds-4", "5f87992db188ccb4f36e946248243b81ab0bc93c199952ceb8043c60ad60c5fa"),
    "libc6": ("2.43-7", "5c71715c51103beb4fbba9fe9f8dff604af6610dfa71c70bff342f54a7860803"),
}

# Bump when the assembly below changes, so cached SDKs are rebuilt.
SDK_LAYOUT_VERSION = 4
PY_TAG = "311"
MULTIARCH = "x86_64-linux-gnu"
WRAP_TOOLS = ("vtkWrapHierarchy-9.6", "vtkWrapPython-9.6", "vtkWrapPythonInit-9.6")
KEPT_LINK_PREFIXES = ("VTK::", "Threads::", "Python3::")


class SetupError(RuntimeError):
    """A setup step failed; the message says what is missing and how to fix it."""


def sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as stream:
        for block in iter(lambda: stream.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def debian_mirror() -> str:
    """The mirror the machine itself uses, so no other host is contacted."""
    sources = Path("/etc/apt/sources.list.d/debian.sources")
    if sources.exists():
        for line in sources.read_text().splitlines():
            if line.startswith("URIs:"):
                return line.split()[1]
    return "http://deb.debian.org/debian"


def download_sid_packages(cache: Path) -> dict[str, Path]:
    """Fetch the pinned sid packages into the cache with a private apt configuration.

    The machine's own apt sources and state are not touched: sid packages are only
    unpacked, never installed.
    """
    apt_dir = cache / "sid-apt"
    debs = cache / "sid-debs"
    debs.mkdir(parents=True, exist_ok=True)
    wanted = {name: debs / f"{name}_{version.replace(':', '%3a')}_amd64.deb"
              for name, (version, _) in SID_PACKAGES.items()}
    missing = [name for name, path in wanted.items()
               if not path.exists() or sha256(path) != SID_PACKAGES[name][1]]
    if missing:
        (apt_dir / "lists" / "partial").mkdir(parents=True, exist_ok=True)
        (apt_dir / "cache" / "archives" / "partial").mkdir(parents=True, exist_ok=True)
        sources_list = apt_dir / "sources.list"
        sources_list.write_text(
            f"deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] {debian_mirror()} sid main\n")
        options = [
            f"-oDir::Etc::SourceList={sources_list}", "-oDir::Etc::SourceParts=/dev/null",
            f"-oDir::State::Lists={apt_dir / 'lists'}", f"-oDir::Cache={apt_dir / 'cache'}",
            "-oAPT::Sandbox::User=root", "-qq"]
        run(["apt-get", *options, "update"], "update the Debian sid package lists")
        pinned = [f"{name}={SID_PACKAGES[name][0]}" for name in missing]
        result = subprocess.run(["apt-get", *options, "download", *pinned], cwd=debs,
                                capture_output=True, text=True)
        if result.returncode != 0:
            raise SetupError(
                "Could not download the pinned Debian sid packages "
                f"{', '.join(pinned)}.\n{result.stderr.strip()}\n"
                "sid may have moved past VTK 9.6.2: the SDK must match the vtk==9.6.2 wheel, "
                "so put the .deb files named above into " f"{debs} by hand, or update the pins "
                "together with the vtk wheel.")
    for name, path in wanted.items():
        if not path.exists():
            raise SetupError(f"Debian sid package {name}={SID_PACKAGES[name][0]} is missing from {debs}")
        actual = sha256(path)
        if actual != SID_PACKAGES[name][1]:
            raise SetupError(f"{path.name}: SHA-256 {actual} differs from the pinned {SID_PACKAGES[name][1]}")
    return wanted


def run(command: list[str], what: str, **kwargs) -> None:
    result = subprocess.run(command, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        raise SetupError(f"Failed to {what}: {' '.join(command)}\n{result.stderr.strip()}")


def wheel_vtk_files(vtk_wheel: Path) -> set[str]:
    with zipfile.ZipFile(vtk_wheel) as archive:
        return {Path(name).name for name in archive.namelist() if name.startswith("vtkmodules/")}


def wheel_library(debian_name: str) -> str:
    """The wheel's file name for a Debian library name such as ``vtkCommonCore``."""
    if debian_name.startswith("vtkWrappingPythonCore"):
        return f"libvtkWrappingPythonCore3.{PY_TAG[1:]}.so"
    return f"lib{debian_name}.so"


def patch_targets_none(text: str, wheel_files: set[str]) -> str:
    def library(match: re.Match) -> str:
        name = match.group(1)
        if name == "vtkWrappingTools":
            return match.group(0)  # used by the sid wrap tools themselves
        return "${VTK_WHEEL_LIBRARY_DIR}/" + wheel_library(name)

    text = re.sub(r"\$\{_IMPORT_PREFIX\}/lib/" + MULTIARCH + r"/lib(vtk[\w.]+?)-9\.6\.so\.9\.6", library, text)
    text = re.sub(r'"lib(vtk(?!WrappingTools)[\w.]+?)-9\.6\.so\.1"',
                  lambda m: '"' + wheel_library(m.group(1)) + '"', text)
    text = re.sub(r"\$\{_IMPORT_PREFIX\}/lib/python3/dist-packages/vtkmodules/(\w+)\.cpython-314-",
                  r"${VTK_WHEEL_LIBRARY_DIR}/\1.cpython-" + PY_TAG + "-", text)
    # Drop existence checks of libraries the wheel does not ship (MPI, Qt, Java, GDAL, ...):
    # a project that never links them must still configure.
    kept = []
    for line in text.splitlines(keepends=True):
        check = re.match(r'list\(APPEND _cmake_import_check_files_for_\S+ "\$\{VTK_WHEEL_LIBRARY_DIR\}/([^"]+)" \)', line)
        if check and check.group(1) not in wheel_files:
            continue
        tool = re.match(r'list\(APPEND _cmake_import_check_files_for_\S+ "\$\{_IMPORT_PREFIX\}/bin/([^"]+)" \)', line)
        if tool and tool.group(1) not in WRAP_TOOLS:
            continue  # Java and JavaScript wrappers are not part of this SDK
        kept.append(line)
    return "".join(kept)


def filter_link_items(items: str) -> str:
    return ";".join(item for item in items.split(";") if _only_kept_targets(item))


def _only_kept_targets(item: str) -> bool:
    targets = re.findall(r"([A-Za-z0-9_]+::[A-Za-z0-9_:-]+)", item)
    return all(target.startswith(KEPT_LINK_PREFIXES) for target in targets)


def patch_targets(text: str) -> str:
    text = re.sub(r'(INTERFACE_LINK_LIBRARIES ")([^"]*)(")',
                  lambda m: m.group(1) + filter_link_items(m.group(2)) + m.group(3), text)
    # The check that every referenced external target exists: only viskores is listed.
    text = re.sub(r'foreach\(_target "viskores::[^)]*\)\n.*?endforeach\(\)\n', "", text, flags=re.S)
    return text


def patch_find_packages(text: str) -> str:
    def replace(match: re.Match) -> str:
        package = match.group(1)
        if package in ("Python3", "Threads"):
            return match.group(0)
        return f"vtk_wheel_provides_package({package}"
    text = re.sub(r"find_package\((\w+)", replace, text)
    text = text.replace("find_package(Python3\n    3.14", f"find_package(Python3\n    3.{PY_TAG[1:]}")
    prelude = (
        "# The vtk wheel links its third-party code into its own libraries: report each\n"
        "# external package as found instead of searching the system for it.\n"
        "macro(vtk_wheel_provides_package package)\n"
        "  set(${package}_FOUND TRUE)\n"
        "endmacro()\n\n")
    return prelude + text


def patch_config(text: str) -> str:
    text = text.replace('_SMP_BACKENDS" "TBB;STDThread;Sequential"', '_SMP_BACKENDS" "STDThread;Sequential"')
    text = text.replace('_HAS_VISKORES" "ON"', '_HAS_VISKORES" "OFF"')
    guard = (
        "if (NOT VTK_WHEEL_LIBRARY_DIR OR NOT EXISTS \"${VTK_WHEEL_LIBRARY_DIR}/libvtkCommonCore.so\")\n"
        "  message(FATAL_ERROR \"This VTK SDK links against the vtk==9.6.2 wheel: set VTK_WHEEL_LIBRARY_DIR \"\n"
        "    \"to the wheel's site-packages/vtkmodules folder (got '${VTK_WHEEL_LIBRARY_DIR}').\")\n"
        "endif ()\n")
    return guard + text


def patch_smp_header(text: str) -> str:
    values = {"VTK_SMP_ENABLE_OPENMP": 0, "VTK_SMP_ENABLE_SEQUENTIAL": 1,
              "VTK_SMP_ENABLE_STDTHREAD": 1, "VTK_SMP_ENABLE_TBB": 0}
    for macro, value in values.items():
        text, count = re.subn(rf"#define {macro} \d", f"#define {macro} {value}", text)
        if count != 1:
            raise SetupError(f"vtkSMP.h: expected one definition of {macro}")
    text = re.sub(r"#define VTK_SMP_DEFAULT_IMPLEMENTATION_\w+ 1", "#define VTK_SMP_DEFAULT_IMPLEMENTATION_STDTHREAD 1", text)
    return text


def wrap_tool_script(real_tool: Path, root: Path) -> str:
    libs = f"{root}/usr/lib/{MULTIARCH}"
    return ("#!/bin/sh\n"
            "# sid's VTK wrap tools need sid's glibc: run them through sid's own loader.\n"
            f'exec "{libs}/ld-linux-x86-64.so.2" --library-path "{libs}" "{real_tool}" "$@"\n')


def assemble(cache: Path, vtk_wheel: Path) -> Path:
    """Build (once) and return the VTK_DIR of the assembled SDK."""
    version = SID_PACKAGES["libvtk9-dev"][0]
    root = cache / f"vtk-sdk-{version}-cp{PY_TAG}-v{SDK_LAYOUT_VERSION}"
    vtk_dir = root / "usr" / "lib" / MULTIARCH / "cmake" / "vtk-9.6"
    stamp = root / ".complete"
    if stamp.exists():
        return vtk_dir
    debs = download_sid_packages(cache)
    staging = root.with_name(root.name + ".partial")
    shutil.rmtree(staging, ignore_errors=True)
    for path in debs.values():
        run(["dpkg-deb", "-x", str(path), str(staging)], f"unpack {path.name}")
    staged_cmake = staging / "usr" / "lib" / MULTIARCH / "cmake" / "vtk-9.6"
    wheel_files = wheel_vtk_files(vtk_wheel)
    for name in ("VTK-targets-none.cmake", "VTKPython-targets-none.cmake"):
        path = staged_cmake / name
        path.write_text(patch_targets_none(path.read_text(), wheel_files))
    for name, patch in (("VTK-targets.cmake", patch_targets),
                        ("VTK-vtk-module-find-packages.cmake", patch_find_packages),
                        ("vtk-config.cmake", patch_config)):
        path = staged_cmake / name
        path.write_text(patch(path.read_text()))
    smp = staging / "usr" / "include" / "vtk-9.6" / "vtkSMP.h"
    smp.write_text(patch_smp_header(smp.read_text()))
    libexec = staging / "usr" / "libexec" / "vtk-wrap-tools"
    libexec.mkdir(parents=True)
    for tool in WRAP_TOOLS:
        binary = staging / "usr" / "bin" / tool
        real = libexec / tool
        binary.rename(real)
        # The script names the final location, so it is written for ``root``.
        binary.write_text(wrap_tool_script(root / "usr" / "libexec" / "vtk-wrap-tools" / tool, root))
        binary.chmod(0o755)
    shutil.rmtree(root, ignore_errors=True)
    staging.rename(root)
    check_wrap_tool(root)
    stamp.write_text(f"{version}\n")
    return vtk_dir


def check_wrap_tool(root: Path) -> None:
    tool = root / "usr" / "bin" / "vtkWrapHierarchy-9.6"
    result = subprocess.run([str(tool), "--help"], capture_output=True, text=True)
    if "Usage" not in (result.stdout + result.stderr):
        raise SetupError(f"The sid wrap tool {tool} does not run:\n{result.stderr.strip()}")


if __name__ == "__main__":
    cache_dir = Path(sys.argv[1])
    wheel = Path(sys.argv[2])
    print(assemble(cache_dir, wheel))
