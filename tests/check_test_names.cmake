# SPDX-License-Identifier: MIT
# catch_discover_tests splits a test name at ';' into several CTest entries that match no test
# case and pass without running anything: refuse such names.
execute_process(COMMAND "${TESTS}" --list-test-names-only RESULT_VARIABLE rc OUTPUT_VARIABLE out)
string(FIND "${out}" ";" at)
if(NOT at EQUAL -1)
  string(SUBSTRING "${out}" 0 ${at} before)
  string(REGEX REPLACE ".*\n" "" name "${before}")
  message(FATAL_ERROR "a Catch2 test name contains ';' (CTest would not run it): '${name}...'")
endif()
string(REGEX MATCHALL "\n" lines "${out}")
list(LENGTH lines n)
message(STATUS "${n} test names checked")
