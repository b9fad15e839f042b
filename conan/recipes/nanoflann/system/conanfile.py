# SPDX-License-Identifier: MIT
# Offline stand-in for ConanCenter's nanoflann/1.4.3: packages Debian's libnanoflann-dev header
# under the same package, file and target names (nanoflann::nanoflann), so taxel's recipe
# resolves with no network. Not a general-purpose recipe.
import os

from conan import ConanFile
from conan.errors import ConanInvalidConfiguration
from conan.tools.files import copy

SYSTEM_HEADER_DIR = "/usr/include"


class NanoflannDebianConan(ConanFile):
    name = "nanoflann"
    description = "nanoflann header taken from Debian's libnanoflann-dev (offline wrapper)"
    license = "BSD-2-Clause"
    package_type = "header-library"
    settings = "os", "arch", "compiler", "build_type"
    no_copy_source = True

    def package_id(self):
        self.info.clear()

    def validate(self):
        if not os.path.isfile(os.path.join(SYSTEM_HEADER_DIR, "nanoflann.hpp")):
            raise ConanInvalidConfiguration(
                "/usr/include/nanoflann.hpp not found: install Debian's libnanoflann-dev")

    def package(self):
        copy(self, "nanoflann.hpp", SYSTEM_HEADER_DIR,
             os.path.join(self.package_folder, "include"))

    def package_info(self):
        self.cpp_info.set_property("cmake_file_name", "nanoflann")
        self.cpp_info.set_property("cmake_target_name", "nanoflann::nanoflann")
        self.cpp_info.set_property("pkg_config_name", "nanoflann")
        self.cpp_info.bindirs = []
        self.cpp_info.libdirs = []
