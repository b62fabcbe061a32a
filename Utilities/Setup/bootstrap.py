"""Set up everything VolumeCutting needs on a fresh Debian 12 machine, idempotently.

Run by both README commands (through Utilities/vc). Each step checks first and only
does what is missing:

1. Debian bookworm packages (compiler, CMake, Ninja, hidapi, libusb, umockdev, Mesa EGL,
   Chromium, the browser the web application's tests drive, and the PostgreSQL server the
   trainee-records tests start);
2. the project virtual environment ``.venv`` with the exact wheels of
   ``requirements.lock`` and, without their declared dependencies, of
   ``requirements-nodeps.lock`` (hash-checked), downloaded once into the cache;
3. the VTK 9.6.2 SDK matching the vtk wheel, assembled from Debian sid (vtk_sdk.py);
4. the slicer-core-sdk adjustments (slicer_sdk.py);
5. the real head CT (Debian's invesalius-examples), cached;
6. ``build/platform.cmake``: the paths CMake needs, for every build of this checkout.

Downloads are cached in ``$VOLUMECUTTING_CACHE`` (default ``~/.cache/volumecutting``),
never in the repository. A step that cannot be done stops with a message naming
what is missing.
"""

from __future__ import annotations

import argparse
import hashlib
import os
import platform
import shutil
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import slicer_sdk  # noqa: E402
import vtk_sdk  # noqa: E402
from vtk_sdk import SetupError  # noqa: E402

REPO = HERE.parent.parent
PYTHON_VERSION = (3, 11)
APT_PACKAGES = [
    "g++", "cmake", "ninja-build", "pkg-config",
    # Utilities/vc compiles through it when present: a fresh clone on the same machine recompiles only what changed.
    "ccache",
    "libhidapi-dev", "libusb-1.0-0-dev",
    # The device backends' tests fake USB and hidraw devices in user space.
    "umockdev", "libumockdev-dev",
    # Offscreen rendering without a display: VTK falls back to EGL on Mesa.
    "libegl1", "libegl-mesa0", "libgl1-mesa-dri",
    # The browser that Playwright drives in the web application's tests (no browser download).
    "chromium",
    # The PostgreSQL server (15) that the trainee-records tests start on a temporary cluster.
    "postgresql",
    # PortAudio, which sounddevice loads for the desktop drill sound (without it the session runs silent).
    "libportaudio2",
]


def cache_dir() -> Path:
    default = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "volumecutting"
    path = Path(os.environ.get("VOLUMECUTTING_CACHE", default))
    path.mkdir(parents=True, exist_ok=True)
    return path


def say(message: str) -> None:
    print(f"[setup] {message}", flush=True)


def check_machine() -> None:
    if sys.version_info[:2] != PYTHON_VERSION:
        raise SetupError(
            f"Python {PYTHON_VERSION[0]}.{PYTHON_VERSION[1]} is required (the pinned vtk and slicer-core "
            f"wheels and the VTK SDK are built for cp311); this is {platform.python_version()} at {sys.executable}. "
            "Run the command with a python3.11 on PATH.")
    if platform.system() != "Linux" or platform.machine() != "x86_64":
        raise SetupError(f"Linux x86_64 is required, this is {platform.system()} {platform.machine()}")
    for tool in ("apt-get", "dpkg-deb", "dpkg-query"):
        if not shutil.which(tool):
            raise SetupError(f"'{tool}' is missing: setup needs a Debian 12 (bookworm) machine")


def missing_apt_packages() -> list[str]:
    missing = []
    for package in APT_PACKAGES:
        result = subprocess.run(["dpkg-query", "-W", "-f=${Status}", package], capture_output=True, text=True)
        if "install ok installed" not in result.stdout:
            missing.append(package)
    return missing


def ensure_apt_packages() -> None:
    missing = missing_apt_packages()
    if not missing:
        return
    if os.geteuid() != 0:
        raise SetupError(f"Debian packages missing: {' '.join(missing)}. Install them with: "
                         f"sudo apt-get install {' '.join(missing)}")
    say(f"installing Debian packages: {' '.join(missing)}")
    vtk_sdk.run(["apt-get", "update", "-qq"], "update the Debian package lists")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    result = subprocess.run(["apt-get", "install", "-y", "-qq", "--no-install-recommends", *missing],
                            capture_output=True, text=True, env=env)
    if result.returncode != 0:
        raise SetupError(f"apt-get could not install {' '.join(missing)}:\n{result.stderr.strip()}")


def venv_python() -> Path:
    return REPO / ".venv" / "bin" / "python"


def site_packages() -> Path:
    return REPO / ".venv" / "lib" / f"python{PYTHON_VERSION[0]}.{PYTHON_VERSION[1]}" / "site-packages"


def _pip(arguments: list[str], what: str) -> None:
    result = subprocess.run([str(venv_python()), "-m", "pip", "--disable-pip-version-check", *arguments],
                            capture_output=True, text=True)
    if result.returncode != 0:
        raise SetupError(f"{what}:\n{result.stderr.strip()[-2000:]}")


def ensure_venv(cache: Path) -> None:
    locks = [HERE / "requirements.lock", HERE / "requirements-nodeps.lock"]
    lock_hash = hashlib.sha256(b"".join(lock.read_bytes() for lock in locks)).hexdigest()
    stamp = REPO / ".venv" / ".volumecutting-lock"
    if venv_python().exists() and stamp.exists() and stamp.read_text().strip() == lock_hash:
        return
    if not venv_python().exists():
        say("creating the virtual environment .venv")
        vtk_sdk.run([sys.executable, "-m", "venv", str(REPO / ".venv")], "create .venv")
    wheels = cache / "wheels"
    wheels.mkdir(exist_ok=True)
    say("fetching the pinned wheels (cached in " f"{wheels})")
    for lock in locks:
        _pip(["download", "-q", "--only-binary=:all:", "--require-hashes", "--no-deps", "-d", str(wheels), "-r", str(lock)],
             f"Could not obtain the pinned wheels of Utilities/Setup/{lock.name} (is PyPI reachable?)")
    say("installing the pinned wheels into .venv")
    offline = ["install", "-q", "--no-index", "--find-links", str(wheels), "--require-hashes", "--only-binary=:all:"]
    _pip([*offline, "-r", str(locks[0])], "Installing the pinned wheels failed")
    # Their declared dependencies are not what this product pins (see the file): installed as they are.
    _pip([*offline, "--no-deps", "-r", str(locks[1])], f"Installing the wheels of {locks[1].name} failed")
    stamp.write_text(lock_hash + "\n")


def vtk_wheel_file(cache: Path) -> Path:
    candidates = sorted((cache / "wheels").glob("vtk-9.6.2-cp311-*.whl"))
    if not candidates:
        raise SetupError(f"the vtk 9.6.2 wheel is missing from {cache / 'wheels'}")
    return candidates[0]


def fetch_head_ct(cache: Path) -> Path | None:
    """Fetch the real head CT with the project's own loader, as a user's machine does."""
    code = ("import sys; sys.path.insert(0, sys.argv[1]); from VolumeCuttingLib.data import headct; "
            "print(headct.fetch(sys.argv[2]))")
    result = subprocess.run(
        [str(venv_python()), "-c", code, str(REPO / "Modules" / "Scripted" / "VolumeCuttingTools"), str(cache / "data")],
        capture_output=True, text=True)
    if result.returncode != 0:
        raise SetupError(f"Could not obtain the head CT:\n{result.stderr.strip()[-2000:]}")
    return Path(result.stdout.strip().splitlines()[-1])


def write_platform_file(vtk_dir: Path, sdk_dir: Path) -> Path:
    build = REPO / "build"
    build.mkdir(exist_ok=True)
    platform_file = build / "platform.cmake"
    text = (
        "# Written by Utilities/Setup/bootstrap.py: where this machine's pinned SDKs are.\n"
        f'set(VTK_DIR "{vtk_dir}" CACHE PATH "")\n'
        f'set(VTK_WHEEL_LIBRARY_DIR "{site_packages() / "vtkmodules"}" CACHE PATH "")\n'
        f'set(slicer_core_sdk_DIR "{sdk_dir}" CACHE PATH "")\n'
        f'set(Python3_EXECUTABLE "{venv_python()}" CACHE FILEPATH "")\n'
        'set(VolumeCutting_BUILD_WITH_SLICER_CORE ON CACHE BOOL "")\n')
    if not platform_file.exists() or platform_file.read_text() != text:
        platform_file.write_text(text)
    return platform_file


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--skip-data", action="store_true", help="do not fetch the real head CT")
    args = parser.parse_args()
    try:
        check_machine()
        cache = cache_dir()
        ensure_apt_packages()
        ensure_venv(cache)
        vtk_dir = vtk_sdk.assemble(cache, vtk_wheel_file(cache))
        sdk_dir = slicer_sdk.patch(site_packages())
        platform_file = write_platform_file(vtk_dir, sdk_dir)
        if not args.skip_data:
            fetch_head_ct(cache)
        say(f"ready ({platform_file.relative_to(REPO)})")
    except (SetupError, RuntimeError) as error:
        print(f"[setup] ERROR: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
