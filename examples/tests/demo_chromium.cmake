# SPDX-License-Identifier: MIT
# Loads the demo's index.html in headless Chromium: every picture must load and every 3-D view
# must draw (the page's own script checks both), and a screenshot of one 3-D view alone must
# show its points (counted in the PNG by png_ink.py).
if(NOT EXISTS "${PAGE}")
  message(FATAL_ERROR "${PAGE} does not exist: run the taxel_demo_quick test first")
endif()
set(flags --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking
          --disable-component-update --disable-sync --user-data-dir=${WORK_DIR}/chromium-profile
          --virtual-time-budget=10000)
execute_process(COMMAND "${CHROMIUM}" ${flags} --dump-dom "file://${PAGE}"
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
set(pictures ${CMAKE_MATCH_1})
if(NOT dom MATCHES "data-status=\"ok\">([0-9]+) 3-D views rendered")
  string(REGEX MATCH "id=\"view-check\"[^<]*" status "${dom}")
  message(FATAL_ERROR "index.html: ${status}")
endif()
if(CMAKE_MATCH_1 LESS MIN_VIEWS)
  message(FATAL_ERROR "index.html has ${CMAKE_MATCH_1} 3-D views, expected at least ${MIN_VIEWS}")
endif()
set(views ${CMAKE_MATCH_1})
if(NOT dom MATCHES "<footer>taxel [0-9]+\\.[0-9]+\\.[0-9]+ [^<]*built ")
  message(FATAL_ERROR "index.html has no version and build stamp")
endif()
# The first fused cloud's view alone, as a screenshot: its points must be there.
file(REMOVE "${WORK_DIR}/view.png")
execute_process(COMMAND "${CHROMIUM}" ${flags} --window-size=490,410
                        --screenshot=${WORK_DIR}/view.png "file://${PAGE}#solo=view-sphere-40"
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 120)
if(NOT rc EQUAL 0 OR NOT EXISTS "${WORK_DIR}/view.png")
  message(FATAL_ERROR "chromium --screenshot failed (${rc}):\n${err}")
endif()
execute_process(COMMAND "${PYTHON}" "${CMAKE_CURRENT_LIST_DIR}/png_ink.py" "${WORK_DIR}/view.png"
                        500 6
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "the 3-D view's screenshot is blank or nearly so: ${out}${err}")
endif()
message(STATUS "chromium: ${pictures} pictures loaded, ${views} 3-D views drawn; ${out}")
