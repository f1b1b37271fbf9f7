"""Builds tetseg's extension modules with the project's CMake build (docs/python.md).

Environment:
  TETSEG_SOURCE_DIR       the repository (default: the folder above this one)
  TETSEG_PIP_BUILD_DIR    CMake build folder (default: <repository>/build-pip)
  TETSEG_PIP_PREPROCESS   OFF to leave out tetseg.preprocess (the GPL, CGAL-linked module)
  TETSEG_JOBS             parallel build jobs (default: CMake's choice)
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = Path(os.environ.get("TETSEG_SOURCE_DIR", HERE.parent)).resolve()
PREPROCESS = os.environ.get("TETSEG_PIP_PREPROCESS", "ON").upper() not in ("OFF", "0", "NO")


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"project\(tetseg VERSION ([0-9.]+)", text)
    if not match:
        raise RuntimeError(f"no project version in {ROOT / 'CMakeLists.txt'}")
    return match.group(1)


class CMakeExtension(Extension):
    """An extension module built by CMake target `target`."""

    def __init__(self, name, target):
        super().__init__(name, sources=[])
        self.target = target


class CMakeBuild(build_ext):
    def run(self):
        if not (ROOT / "CMakeLists.txt").exists():
            raise RuntimeError(f"{ROOT} is not the tetseg repository (set TETSEG_SOURCE_DIR)")
        build_dir = Path(os.environ.get("TETSEG_PIP_BUILD_DIR", ROOT / "build-pip"))
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
            f"-DPython_EXECUTABLE={sys.executable}", "-DTETSEG_BUILD_PYTHON=ON",
            "-DTETSEG_BUILD_TOOLS=OFF", "-DTETSEG_BUILD_TESTS=OFF", "-DTETSEG_INSTALL=OFF",
            f"-DTETSEG_BUILD_PREPROCESS={'ON' if PREPROCESS else 'OFF'}",
        ]
        if shutil.which("ninja") and not (build_dir / "CMakeCache.txt").exists():
            configure += ["-G", "Ninja"]
        subprocess.run(configure, check=True)
        command = ["cmake", "--build", str(build_dir), "--target"]
        command += [ext.target for ext in self.extensions]
        if os.environ.get("TETSEG_JOBS"):
            command += ["-j", os.environ["TETSEG_JOBS"]]
        subprocess.run(command, check=True)
        for ext in self.extensions:
            built = build_dir / "python" / Path(self.get_ext_filename(ext.name))
            if not built.exists():
                raise RuntimeError(f"CMake did not produce {built}")
            destination = Path(self.get_ext_fullpath(ext.name))
            destination.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(built, destination)


extensions = [CMakeExtension("tetseg._runtime", "tetseg_python_runtime")]
if PREPROCESS:
    extensions.append(CMakeExtension("tetseg.preprocess", "tetseg_python_preprocess"))

setup(
    version=project_version(),
    packages=["tetseg"],
    package_dir={"tetseg": "tetseg"},
    package_data={"tetseg": ["py.typed", "_runtime.pyi"] + (["preprocess.pyi"] if PREPROCESS else [])},
    ext_modules=extensions,
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
)
