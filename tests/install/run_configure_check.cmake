# SPDX-License-Identifier: MIT
# ctest script: configuring taxel with DEPENDENCY hidden must fail and name the Debian package.
file(REMOVE_RECURSE "${WORK_DIR}")
set(expected_Eigen3 "libeigen3-dev")
set(expected_nanoflann "libnanoflann-dev")
set(expected_nanoflann15 "1.5.0.*libnanoflann-dev")
if(DEPENDENCY STREQUAL "nanoflann15")
  # A nanoflann of the wrong (newer, API-breaking) version is the only one visible.
  set(hide "-Dnanoflann_DIR=${TAXEL_SOURCE_DIR}/tests/install/fake_nanoflann_1_5"
           "-DCMAKE_IGNORE_PATH=${REAL_NANOFLANN_DIR}")
else()
  set(hide "-DCMAKE_DISABLE_FIND_PACKAGE_${DEPENDENCY}=ON")
endif()
execute_process(
  COMMAND ${CMAKE_COMMAND} -S "${TAXEL_SOURCE_DIR}" -B "${WORK_DIR}"
          ${hide} -DTAXEL_BUILD_TESTS=OFF
          -DTAXEL_BUILD_EXAMPLES=OFF -DTAXEL_BUILD_BENCHMARKS=OFF -DTAXEL_BUILD_DRIVERS=OFF
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(rc EQUAL 0)
  message(FATAL_ERROR "configure succeeded although ${DEPENDENCY} was hidden")
endif()
if(NOT err MATCHES "${expected_${DEPENDENCY}}")
  message(FATAL_ERROR "configure failed without naming ${expected_${DEPENDENCY}}:\n${err}")
endif()
message(STATUS "configure failed as expected:\n${err}")
file(REMOVE_RECURSE "${WORK_DIR}")
