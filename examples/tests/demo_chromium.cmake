# SPDX-License-Identifier: MIT
# Loads the demo's index.html in headless Chromium: every picture must load (the page's own
# script reports broken ones).
if(NOT EXISTS "${PAGE}")
  message(FATAL_ERROR "${PAGE} does not exist: run the taxel_demo_quick test first")
endif()
execute_process(COMMAND "${CHROMIUM}" --headless --no-sandbox --disable-gpu
                        --virtual-time-budget=10000 --dump-dom "file://${PAGE}"
                RESULT_VARIABLE rc OUTPUT_VARIABLE dom ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "chromium failed (${rc}):\n${err}")
endif()
if(NOT dom MATCHES "data-status=\"ok\">all ([0-9]+) pictures loaded")
  string(REGEX MATCH "id=\"image-check\"[^<]*" status "${dom}")
  message(FATAL_ERROR "index.html: ${status}")
endif()
if(CMAKE_MATCH_1 LESS MIN_PICTURES)
  message(FATAL_ERROR "index.html shows ${CMAKE_MATCH_1} pictures, expected at least ${MIN_PICTURES}")
endif()
message(STATUS "chromium: all ${CMAKE_MATCH_1} pictures loaded")
