# SPDX-License-Identifier: MIT
# ctest script: install taxel to a temporary prefix, then configure, build and run consumers
# that find it through find_package, pkg-config and add_subdirectory.
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    string(REPLACE ";" " " cmd "${ARGN}")
    message(FATAL_ERROR "command failed (${rc}): ${cmd}\n${out}\n${err}")
  endif()
  message(STATUS "${out}")
endfunction()

if(CONFIG)
  set(config_arg --config ${CONFIG})
endif()
run(${CMAKE_COMMAND} --install "${TAXEL_BINARY_DIR}" --prefix "${prefix}" ${config_arg})
foreach(f share/cmake/taxel/taxelConfig.cmake share/cmake/taxel/taxelConfigVersion.cmake
          share/cmake/taxel/taxelTargets.cmake share/pkgconfig/taxel.pc include/taxel/taxel.hpp)
  if(NOT EXISTS "${prefix}/${f}")
    message(FATAL_ERROR "install did not produce ${f}")
  endif()
endforeach()

# The tools, when installed, run from the prefix alone (a fresh folder, nothing else on PATH).
if(TOOLS)
  foreach(tool taxel-simulate taxel-fuse taxel-icp taxel-recognize taxel-describe taxel-optical
               taxel-train taxel-predict)
    execute_process(COMMAND "${prefix}/bin/${tool}" --version RESULT_VARIABLE rc
                    OUTPUT_VARIABLE out)
    if(NOT rc EQUAL 0 OR NOT out MATCHES "^${tool} \\(taxel\\) [0-9]+\\.[0-9]+\\.[0-9]+\n$")
      message(FATAL_ERROR "installed ${tool} --version: exit ${rc}, '${out}'")
    endif()
  endforeach()
  file(MAKE_DIRECTORY "${WORK_DIR}/tools")
  run(${CMAKE_COMMAND} -E chdir "${WORK_DIR}/tools"
      "${prefix}/bin/taxel-simulate" --shape box --contacts 2000 contacts.csv truth.ply)
  run(${CMAKE_COMMAND} -E chdir "${WORK_DIR}/tools"
      "${prefix}/bin/taxel-fuse" contacts.csv cloud.ply)
  run(${CMAKE_COMMAND} -E chdir "${WORK_DIR}/tools"
      "${prefix}/bin/taxel-icp" cloud.ply truth.ply)
endif()

set(consumers "${TAXEL_SOURCE_DIR}/tests/install")
foreach(kind cmake pkgconfig subdir)
  set(build "${WORK_DIR}/build_${kind}")
  run(${CMAKE_COMMAND} -E env "PKG_CONFIG_PATH=${prefix}/share/pkgconfig"
      ${CMAKE_COMMAND} -S "${consumers}/consumer_${kind}" -B "${build}"
      "-DCMAKE_PREFIX_PATH=${prefix}" "-DTAXEL_SOURCE_DIR=${TAXEL_SOURCE_DIR}"
      "-DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release)
  run(${CMAKE_COMMAND} --build "${build}")
  run("${build}/consumer")
  if(EXISTS "${build}/consumer_drivers")
    run("${build}/consumer_drivers")
  endif()
endforeach()
# A consumer of three translation units, each including all of taxel and calling different
# parts of it: every header must be safe to include in many files of one program.
set(build "${WORK_DIR}/build_units")
run(${CMAKE_COMMAND} -S "${consumers}/units" -B "${build}" "-DCMAKE_PREFIX_PATH=${prefix}"
    "-DCMAKE_CXX_COMPILER=${CMAKE_CXX_COMPILER}" -DCMAKE_BUILD_TYPE=Release)
run(${CMAKE_COMMAND} --build "${build}" --parallel 2)
run("${build}/consumer")

if(NOT EXISTS "${WORK_DIR}/build_cmake/consumer_drivers" AND NOT NO_DRIVERS)
  message(FATAL_ERROR "the installed package defined no taxel::drivers although libusb is here")
endif()

# The package config must come from the prefix, not from the source or build tree.
file(READ "${WORK_DIR}/build_cmake/CMakeCache.txt" cache)
if(NOT cache MATCHES "taxel_DIR:PATH=${prefix}/share/cmake/taxel")
  message(FATAL_ERROR "consumer found taxel somewhere other than ${prefix}")
endif()
