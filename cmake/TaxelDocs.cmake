# SPDX-License-Identifier: MIT
# The API reference (target `docs`, Doxygen) and the tests that keep the README and the guide
# honest: paragraph length, code blocks that compile and run, links that resolve in a browser,
# and a reference without Doxygen warnings.
find_package(Doxygen QUIET)
set(TAXEL_DOCS_DIR "${CMAKE_BINARY_DIR}/docs")
if(DOXYGEN_FOUND)
  configure_file("${PROJECT_SOURCE_DIR}/docs/Doxyfile.in" "${TAXEL_DOCS_DIR}/Doxyfile" @ONLY)
  add_custom_target(docs
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${TAXEL_DOCS_DIR}"
    COMMAND "${DOXYGEN_EXECUTABLE}" "${TAXEL_DOCS_DIR}/Doxyfile"
    COMMAND "${CMAKE_COMMAND}" -E echo "API reference: ${TAXEL_DOCS_DIR}/html/index.html"
    WORKING_DIRECTORY "${TAXEL_DOCS_DIR}"
    COMMENT "Generating the API reference with Doxygen"
    VERBATIM)
else()
  add_custom_target(docs
    COMMAND "${CMAKE_COMMAND}" -E echo "the API reference needs Doxygen (Debian: apt-get install doxygen)"
    COMMAND "${CMAKE_COMMAND}" -E false
    VERBATIM)
endif()

if(NOT TAXEL_BUILD_TESTS)
  return()
endif()
# Debian's python3 has python3-markdown; a pyenv python3 first on PATH may not.
find_program(TAXEL_DOCS_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
if(NOT TAXEL_DOCS_PYTHON)
  find_program(TAXEL_DOCS_PYTHON NAMES python3)
endif()
if(NOT TAXEL_DOCS_PYTHON)
  message(STATUS "taxel: no python3, the documentation tests are skipped")
  return()
endif()
set(_check "${PROJECT_SOURCE_DIR}/tests/docs/check_docs.py")
add_test(NAME docs_style COMMAND "${TAXEL_DOCS_PYTHON}" "${_check}" style "${PROJECT_SOURCE_DIR}")

if(TAXEL_BUILD_EXAMPLES)
  get_target_property(_eigen_dirs Eigen3::Eigen INTERFACE_INCLUDE_DIRECTORIES)
  set(_flags "-std=c++20 -I${PROJECT_SOURCE_DIR}/include -I${PROJECT_SOURCE_DIR}/drivers/include")
  foreach(_d IN LISTS _eigen_dirs)
    string(APPEND _flags " -isystem ${_d}")
  endforeach()
  set(_tools "$<TARGET_FILE_DIR:taxel-fuse>")
  if(TARGET taxel-record)
    list(APPEND _tools "$<TARGET_FILE_DIR:taxel-record>")
  endif()
  set(_python)
  if(TAXEL_BUILD_PYTHON)
    set(_python --python "${Python_EXECUTABLE}" --pythonpath "${CMAKE_BINARY_DIR}/python")
  endif()
  add_test(NAME docs_examples
    COMMAND "${TAXEL_DOCS_PYTHON}" "${_check}" examples "${PROJECT_SOURCE_DIR}"
            --cxx "${CMAKE_CXX_COMPILER}" --flags "${_flags}" ${_python} --tools ${_tools})
  set_tests_properties(docs_examples PROPERTIES TIMEOUT 900)
endif()

find_program(TAXEL_CHROMIUM NAMES chromium chromium-browser)
execute_process(COMMAND "${TAXEL_DOCS_PYTHON}" -c "import markdown"
                RESULT_VARIABLE _no_markdown OUTPUT_QUIET ERROR_QUIET)
if(TAXEL_CHROMIUM AND _no_markdown EQUAL 0)
  add_test(NAME docs_links_in_chromium
    COMMAND "${TAXEL_DOCS_PYTHON}" "${_check}" links "${PROJECT_SOURCE_DIR}"
            --chromium "${TAXEL_CHROMIUM}" --work "${CMAKE_BINARY_DIR}/docs-links")
  set_tests_properties(docs_links_in_chromium PROPERTIES LABELS browser TIMEOUT 600)
else()
  message(STATUS "taxel: the link check needs chromium and python3-markdown; skipped")
endif()

if(DOXYGEN_FOUND)
  # Builds the reference and fails on any warning (an undocumented public member, a bad
  # command in a comment).
  add_test(NAME docs_doxygen_without_warnings
    COMMAND "${CMAKE_COMMAND}" -DDOXYGEN=${DOXYGEN_EXECUTABLE} -DDIR=${TAXEL_DOCS_DIR}
            -P "${PROJECT_SOURCE_DIR}/tests/docs/doxygen_check.cmake")
else()
  message(STATUS "taxel: doxygen not found; the API reference test is skipped")
endif()
