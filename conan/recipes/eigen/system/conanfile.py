# SPDX-License-Identifier: MIT
# Offline stand-in for ConanCenter's eigen/3.4.0: packages Debian's libeigen3-dev headers under
# the same package, file and target names (Eigen3::Eigen), so taxel's recipe resolves with no
# network. Not a general-purpose recipe.
import os
import re

from conan import ConanFile
from conan.errors import ConanInvalidConfiguration
from conan.tools.files import copy, load

SYSTEM_INCLUDE = "/usr/include/eigen3"


class EigenDebianConan(ConanFile):
    name = "eigen"
    description = "Eigen headers taken from Debian's libeigen3-dev (offline wrapper)"
    license = "MPL-2.0"
    package_type = "header-library"
    settings = "os", "arch", "compiler", "build_type"
    no_copy_source = True

    def package_id(self):
        self.info.clear()

    def _system_version(self):
        macros = os.path.join(SYSTEM_INCLUDE, "Eigen", "src", "Core", "util", "Macros.h")
        if not os.path.isfile(macros):
            raise ConanInvalidConfiguration(
                f"{macros} not found: install Debian's libeigen3-dev")
        text = load(self, macros)
        parts = [re.search(rf"#define EIGEN_{k}_VERSION (\d+)", text).group(1)
                 for k in ("WORLD", "MAJOR", "MINOR")]
        return ".".join(parts)

    def validate(self):
        found = self._system_version()
        if found != str(self.version):
            raise ConanInvalidConfiguration(
                f"Debian's Eigen is {found}, this wrapper packages {self.version}")

    def package(self):
        self._system_version()
        copy(self, "*", SYSTEM_INCLUDE, os.path.join(self.package_folder, "include", "eigen3"))

    def package_info(self):
        self.cpp_info.set_property("cmake_file_name", "Eigen3")
        self.cpp_info.set_property("cmake_target_name", "Eigen3::Eigen")
        self.cpp_info.set_property("pkg_config_name", "eigen3")
        self.cpp_info.includedirs = ["include/eigen3"]
        self.cpp_info.bindirs = []
        self.cpp_info.libdirs = []
