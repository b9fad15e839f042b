# SPDX-License-Identifier: MIT
# Builds the API reference and requires Doxygen to have said nothing.
file(REMOVE "${DIR}/warnings.txt")
execute_process(COMMAND "${DOXYGEN}" "${DIR}/Doxyfile" WORKING_DIRECTORY "${DIR}"
                RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "doxygen failed (${rc}):\n${err}")
endif()
file(READ "${DIR}/warnings.txt" warnings)
string(STRIP "${warnings}" warnings)
if(NOT warnings STREQUAL "")
  message(FATAL_ERROR "Doxygen warnings on the public headers:\n${warnings}")
endif()
if(NOT EXISTS "${DIR}/html/classtaxel_1_1fusion_1_1ContactCloud.html")
  message(FATAL_ERROR "the reference has no page for taxel::fusion::ContactCloud")
endif()
