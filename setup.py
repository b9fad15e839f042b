# SPDX-License-Identifier: MIT
"""Builds taxel._taxel with the project's CMake build, so pip and `cmake --install` install the
same module. Needs cmake, a C++20 compiler, pybind11 (pybind11-dev), Eigen and nanoflann.
TAXEL_CMAKE_ARGS adds options to the CMake configure step."""
import os
import pathlib
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = pathlib.Path(self.build_temp).resolve() / "cmake"
        config = [
            "cmake", "-S", str(ROOT), "-B", str(build),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DTAXEL_BUILD_PYTHON=ON",
            "-DTAXEL_BUILD_TESTS=OFF",
            "-DTAXEL_BUILD_EXAMPLES=OFF",
            "-DTAXEL_BUILD_BENCHMARKS=OFF",
            "-DTAXEL_BUILD_DRIVERS=OFF",
            "-DTAXEL_INSTALL=OFF",
            f"-DPython_EXECUTABLE={sys.executable}",
        ] + shlex.split(os.environ.get("TAXEL_CMAKE_ARGS", ""))
        subprocess.run(config, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", str(build), "--target", "taxel_python", "-j", jobs], check=True)
        built = next((build / "python" / "taxel").glob("_taxel*" + os.path.splitext(self.get_ext_filename("x"))[1]))
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(ext_modules=[Extension("taxel._taxel", sources=[])], cmdclass={"build_ext": CMakeBuild})
