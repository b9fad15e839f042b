# SPDX-License-Identifier: MIT
# Install rules: headers, exported target, CMake package files and pkg-config file.
include(CMakePackageConfigHelpers)

set(TAXEL_INSTALL_CMAKEDIR "${CMAKE_INSTALL_DATADIR}/cmake/taxel"
    CACHE STRING "Where taxelConfig.cmake is installed, relative to the prefix")

install(DIRECTORY include/taxel DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
# The driver headers too: taxelConfig.cmake defines taxel::drivers where libusb-1.0 is found.
install(DIRECTORY drivers/include/taxel DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
install(TARGETS taxel EXPORT taxelTargets)
install(EXPORT taxelTargets NAMESPACE taxel:: DESTINATION ${TAXEL_INSTALL_CMAKEDIR})

configure_package_config_file(cmake/taxelConfig.cmake.in
  "${PROJECT_BINARY_DIR}/taxelConfig.cmake"
  INSTALL_DESTINATION ${TAXEL_INSTALL_CMAKEDIR})
# Minor versions may break the API while taxel is 0.x.
write_basic_package_version_file("${PROJECT_BINARY_DIR}/taxelConfigVersion.cmake"
  COMPATIBILITY SameMinorVersion ARCH_INDEPENDENT)
install(FILES "${PROJECT_BINARY_DIR}/taxelConfig.cmake"
              "${PROJECT_BINARY_DIR}/taxelConfigVersion.cmake"
        DESTINATION ${TAXEL_INSTALL_CMAKEDIR})

configure_file(cmake/taxel.pc.in "${PROJECT_BINARY_DIR}/taxel.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/taxel.pc" DESTINATION ${CMAKE_INSTALL_DATADIR}/pkgconfig)
install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/taxel)
