# SPDX-License-Identifier: MIT
# Finds taxel's required dependencies and fails early with the Debian package to install.
include(GNUInstallDirs)

macro(taxel_find_core_dependencies)
  find_package(Eigen3 3.3 QUIET NO_MODULE)
  if(NOT Eigen3_FOUND OR NOT TARGET Eigen3::Eigen)
    message(FATAL_ERROR
      "taxel needs Eigen >= 3.3 (found: ${Eigen3_VERSION}${EIGEN3_VERSION_STRING}). "
      "On Debian/Ubuntu install it with: sudo apt-get install libeigen3-dev "
      "(or point CMAKE_PREFIX_PATH at an Eigen installation).")
  endif()

  # Debian 12 ships nanoflann 1.4.3 whose CMake files say 1.4.2; nanoflann 1.5 changed its API.
  find_package(nanoflann 1.4...<1.5 QUIET)
  if(NOT nanoflann_FOUND OR NOT TARGET nanoflann::nanoflann)
    if(nanoflann_CONSIDERED_VERSIONS)
      set(_taxel_nf_seen " (found incompatible version(s): ${nanoflann_CONSIDERED_VERSIONS})")
    else()
      set(_taxel_nf_seen " (not found)")
    endif()
    message(FATAL_ERROR
      "taxel needs nanoflann 1.4.x${_taxel_nf_seen}; nanoflann 1.5 changed its API. "
      "On Debian 12 install it with: sudo apt-get install libnanoflann-dev "
      "(or point CMAKE_PREFIX_PATH at a nanoflann 1.4 installation).")
  endif()
endmacro()
