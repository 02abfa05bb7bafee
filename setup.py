"""Builds the Python package `plenoptic` (distribution plenoptic-gi) through CMake.

    python3 -m venv --system-site-packages .venv && .venv/bin/pip install --no-build-isolation .

The extension plenoptic._plenoptic is the CMake target plenoptic_python, built for the
interpreter running this (its base interpreter in a venv), with ccache where the project's
CMake finds it; nothing is downloaded. The CMake build directory is
  - $PLENOPTIC_BUILD_DIR when set (configured here unless it is already; it must be for this
    interpreter),
  - else build/ (the Makefile's) when it is configured for this interpreter, so that after
    `make build` an install only links what is missing,
  - else build-python-<tag>/ of its own (a Release build of the library and the extension
    alone, no tests or benchmarks).
The package's Python files (__init__.py, __init__.pyi, py.typed) come from src/python/plenoptic/.
Metadata: pyproject.toml; the version is the one in CMakeLists.txt.
"""
import hashlib
import os
import re
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
SETUPTOOLS_DIR = ROOT / "build" / "setuptools"
SETUPTOOLS_DIR.mkdir(parents=True, exist_ok=True)


def project_version():
    """The version of `project(plenoptic VERSION x.y.z)` in CMakeLists.txt."""
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"project\(\s*plenoptic\s+VERSION\s+([0-9][0-9.]*)", text)
    if not match:
        sys.exit("setup.py: no `project(plenoptic VERSION ...)` in CMakeLists.txt")
    return match.group(1)


def interpreter():
    """The interpreter the extension is for: this one, or in a venv the one it was made from
    (the same headers and ABI; a venv's python is a link to it)."""
    return os.path.realpath(getattr(sys, "_base_executable", None) or sys.executable)


def cached(build_dir, variable):
    """`variable`'s value in build_dir's CMakeCache.txt, or None."""
    cache = Path(build_dir) / "CMakeCache.txt"
    if not cache.is_file():
        return None
    for line in cache.read_text(errors="replace").splitlines():
        name, _, value = line.partition("=")
        if name.split(":")[0] == variable:
            return value
    return None


def cached_interpreter(build_dir):
    """The Python build_dir is configured for: -DPython3_EXECUTABLE, else the one FindPython
    found and cached (as _Python3_EXECUTABLE); None when build_dir is not configured."""
    return cached(build_dir, "Python3_EXECUTABLE") or cached(build_dir, "_Python3_EXECUTABLE")


def configured_for_this_interpreter(build_dir):
    python = cached_interpreter(build_dir)
    return python is not None and os.path.realpath(python) == interpreter()


def cmake_build_dir():
    given = os.environ.get("PLENOPTIC_BUILD_DIR")
    if given:
        return Path(given).resolve()
    if configured_for_this_interpreter(ROOT / "build"):
        return ROOT / "build"
    tag = hashlib.sha256(interpreter().encode()).hexdigest()[:8]
    return ROOT / f"build-python-{sys.implementation.cache_tag}-{tag}"


def run(command, env):
    print("setup.py:", " ".join(str(c) for c in command), flush=True)
    subprocess.run([str(c) for c in command], check=True, env=env)


class CMakeBuild(build_ext):
    """Builds plenoptic._plenoptic with CMake and copies it where setuptools packs it."""

    def build_extension(self, ext):
        cmake = shutil.which("cmake")
        if cmake is None:
            sys.exit("setup.py: cmake is not installed (Debian: apt-get install cmake, or scripts/bootstrap.sh)")
        build_dir = cmake_build_dir()
        env = dict(os.environ)
        env.setdefault("CCACHE_BASEDIR", str(ROOT))  # cache hits across build directories of this clone
        python = cached_interpreter(build_dir)
        if python is None:
            run([cmake, "-S", ROOT, "-B", build_dir, "-DCMAKE_BUILD_TYPE=Release", f"-DPython3_EXECUTABLE={interpreter()}",
                 "-DBUILD_TESTING=OFF", "-DPLENOPTIC_BENCHMARKS=OFF"], env)
        elif os.path.realpath(python) != interpreter():
            sys.exit(f"setup.py: {build_dir} is configured for the Python {python}, not for {interpreter()} that runs "
                     "this install: unset PLENOPTIC_BUILD_DIR (an install then configures a build directory of its own) "
                     "or point it at a build directory of this interpreter")
        if cached(build_dir, "pybind11_DIR") in (None, "pybind11_DIR-NOTFOUND"):
            sys.exit(f"setup.py: CMake found no pybind11 in {build_dir} (Debian: pybind11-dev and python3-dev, "
                     "scripts/bootstrap.sh installs both), so the extension cannot be built")
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        run([cmake, "--build", build_dir, "--target", "plenoptic_python", "-j", jobs], env)
        built = build_dir / "python" / "plenoptic" / ("_plenoptic" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.is_file():
            sys.exit(f"setup.py: the build made no {built} (was {build_dir} configured for another Python?)")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(
    # setuptools' own build files (lib.*, bdist.*, the egg-info) in a folder of their own.
    options={"build": {"build_base": str(SETUPTOOLS_DIR)}, "egg_info": {"egg_base": str(SETUPTOOLS_DIR)}},
    version=project_version(),
    packages=["plenoptic"],
    package_dir={"plenoptic": "src/python/plenoptic"},
    package_data={"plenoptic": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("plenoptic._plenoptic", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
