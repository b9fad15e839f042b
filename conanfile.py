# SPDX-License-Identifier: MIT
# Conan 2 recipe for taxel, a header-only library.
import os
import re

from conan import ConanFile
from conan.tools.build import check_min_cppstd
from conan.tools.files import copy, load
from conan.tools.layout import basic_layout


class TaxelConan(ConanFile):
    name = "taxel"
    description = "Header-only C++20 library for tactile perception"
    license = "MIT"
    url = "https://github.com/taxel-robotics/taxel"
    homepage = "https://github.com/taxel-robotics/taxel"
    topics = ("robotics", "tactile", "point-cloud", "icp", "kalman-filter", "header-only")
    package_type = "header-library"
    settings = "os", "arch", "compiler", "build_type"
    exports_sources = "include/*", "LICENSE"
    no_copy_source = True

    def set_version(self):
        # The one source of truth is project(VERSION) in CMakeLists.txt.
        text = load(self, os.path.join(self.recipe_folder, "CMakeLists.txt"))
        self.version = re.search(r"project\(\s*taxel\s+VERSION\s+([0-9.]+)", text).group(1)

    def layout(self):
        basic_layout(self)

    def requirements(self):
        self.requires("eigen/3.4.0", transitive_headers=True)
        # nanoflann 1.5 changed its API; taxel uses the 1.4 interface.
        self.requires("nanoflann/[>=1.4.3 <1.5]", transitive_headers=True)

    def package_id(self):
        self.info.clear()

    def validate(self):
        check_min_cppstd(self, 20)

    def package(self):
        copy(self, "LICENSE", self.source_folder, os.path.join(self.package_folder, "licenses"))
        copy(self, "*.hpp", os.path.join(self.source_folder, "include"),
             os.path.join(self.package_folder, "include"))

    def package_info(self):
        self.cpp_info.set_property("cmake_file_name", "taxel")
        self.cpp_info.set_property("cmake_target_name", "taxel::taxel")
        self.cpp_info.set_property("pkg_config_name", "taxel")
        self.cpp_info.bindirs = []
        self.cpp_info.libdirs = []
        if self.settings.os in ("Linux", "FreeBSD"):
            self.cpp_info.system_libs = ["pthread"]  # <taxel/core/parallel.hpp> uses std::jthread
