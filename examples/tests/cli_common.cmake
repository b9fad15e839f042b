# SPDX-License-Identifier: MIT
# Helpers of the command-line contract tests (run with cmake -P): a fresh WORK_DIR, running a
# tool there with an expected exit code, and matching its output.
file(REMOVE_RECURSE "${WORK_DIR}")
file(MAKE_DIRECTORY "${WORK_DIR}")

# Runs `tool ARGN` in WORK_DIR; fails unless it exits with expect_rc. Sets `out` and `err`.
function(run_tool tool expect_rc)
  execute_process(COMMAND "${tool}" ${ARGN} WORKING_DIRECTORY "${WORK_DIR}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "${tool} ${ARGN}: exit ${rc}, expected ${expect_rc}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()

function(expect text pattern)
  if(NOT text MATCHES "${pattern}")
    message(FATAL_ERROR "expected /${pattern}/ in:\n${text}")
  endif()
endfunction()

function(expect_one_line text)
  string(STRIP "${text}" t)
  if(t MATCHES "\n")
    message(FATAL_ERROR "expected a one-line error, got:\n${text}")
  endif()
endfunction()
