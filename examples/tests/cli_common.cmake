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

# Like run_tool, with the file `input` (in WORK_DIR) as standard input.
function(run_tool_stdin tool expect_rc input)
  execute_process(COMMAND "${tool}" ${ARGN} WORKING_DIRECTORY "${WORK_DIR}"
                  INPUT_FILE "${WORK_DIR}/${input}"
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL expect_rc)
    message(FATAL_ERROR "${tool} ${ARGN} < ${input}: exit ${rc}, expected ${expect_rc}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
  set(err "${err}" PARENT_SCOPE)
endfunction()

# Parses `text` as JSON (CMake's own parser) and sets `var` to the member at the path ARGN
# (names and array indexes); fails when the text is not JSON or the member is missing.
function(json_get var text)
  string(JSON value ERROR_VARIABLE json_error GET "${text}" ${ARGN})
  if(json_error)
    message(FATAL_ERROR "not valid JSON, or no member ${ARGN}: ${json_error}\n${text}")
  endif()
  set(${var} "${value}" PARENT_SCOPE)
endfunction()

# `--version` prints "<name> (taxel) <version>" and exits 0.
function(expect_version tool name)
  run_tool("${tool}" 0 --version)
  expect("${out}" "^${name} \\(taxel\\) [0-9]+\\.[0-9]+\\.[0-9]+\n$")
endfunction()

# Sets `var` to the number of elements of the array (or members of the object) at ARGN in the
# JSON `text`; fails when the text is not JSON or the member is missing.
function(json_length var text)
  string(JSON value ERROR_VARIABLE json_error LENGTH "${text}" ${ARGN})
  if(json_error)
    message(FATAL_ERROR "not valid JSON, or no member ${ARGN}: ${json_error}\n${text}")
  endif()
  set(${var} "${value}" PARENT_SCOPE)
endfunction()
