#!/usr/bin/env python3
"""ctest python_package: installs the package with pip, as a user would, and runs the test suite
on the installed copy.

    install_test.py --source REPO --build-dir BUILD

1. makes a venv with --system-site-packages (Debian's NumPy, pytest, pip and setuptools) in a
   temporary directory;
2. `pip install --no-build-isolation --no-index --no-cache-dir REPO` into it, with
   PLENOPTIC_BUILD_DIR=BUILD so that setup.py reuses this build (the extension is already
   built: CMake only checks it);
3. copies test_plenoptic.py into a fresh directory outside the source and build trees and runs
   pytest there with the venv's python and no PYTHONPATH, with PLENOPTIC_EXPECT_PACKAGE_IN set
   to the venv: the suite checks that the package it imported is the installed one.

Exits 77 (ctest: skipped) with the reason when venv, pip or setuptools is missing.
"""
import argparse
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile

SKIP = 77


def skip_unless_available():
    missing = []
    for module, package in (("venv", "python3-venv"), ("pip", "python3-pip"), ("setuptools", "python3-setuptools"),
                            ("wheel", "python3-wheel"), ("pytest", "python3-pytest"), ("numpy", "python3-numpy")):
        if importlib.util.find_spec(module) is None:  # found, not imported (pip and setuptools clash)
            missing.append(f"{module} (Debian: {package})")
    if missing:
        print(f"install_test: skipped: {sys.executable} has no {', '.join(missing)}")
        sys.exit(SKIP)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--source", required=True, help="the repository (where pyproject.toml is)")
    parser.add_argument("--build-dir", required=True, help="the CMake build directory to reuse")
    args = parser.parse_args()
    skip_unless_available()

    with tempfile.TemporaryDirectory(prefix="plenoptic-install-") as scratch:
        venv = os.path.join(scratch, "venv")
        # --without-pip: the venv uses Debian's pip through the system site packages (no
        # ensurepip wheel needed), and installs into the venv.
        subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", "--without-pip", venv], check=True)
        python = os.path.join(venv, "bin", "python")
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
        env["PLENOPTIC_BUILD_DIR"] = os.path.abspath(args.build_dir)
        env["PIP_NO_INPUT"] = "1"
        subprocess.run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", "--no-cache-dir",
                        "--quiet", os.path.abspath(args.source)], check=True, env=env, cwd=scratch)

        # The suite, from a directory that is neither the source nor the build tree.
        tests = os.path.join(scratch, "tests")
        os.mkdir(tests)
        shutil.copy(os.path.join(os.path.dirname(os.path.abspath(__file__)), "test_plenoptic.py"), tests)
        env.pop("PLENOPTIC_BUILD_DIR")
        env["PLENOPTIC_EXPECT_PACKAGE_IN"] = venv
        env.setdefault("PLENOPTIC_TEST_DATA", os.path.join(os.path.abspath(args.source), "tests", "data"))
        result = subprocess.run([python, "-m", "pytest", "-q", "-p", "no:cacheprovider", "test_plenoptic.py"],
                                env=env, cwd=tests)
        sys.exit(result.returncode)


if __name__ == "__main__":
    main()
