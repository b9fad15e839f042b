# SPDX-License-Identifier: MIT
# Lost writes are errors, and outputs are written whole or not at all, for every tool:
# - standard output on /dev/full: exit 1 with "cannot write standard output";
# - a file output on a "full disk" (the file size limit at 0, as `ulimit -f 0`, with SIGXFSZ
#   ignored, so every write to a regular file fails with EFBIG): exit 1 naming the file, the
#   previous file unchanged, no temporary file left beside it.
# Run with -DSIMULATE= -DFUSE= -DICP= -DRECOGNIZE= -DDESCRIBE= -DTRAIN= -DPREDICT= -DDEMO=
# -DWORK_DIR=.
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

# Inputs, made by the tools themselves.
run_tool("${SIMULATE}" 0 --contacts 3000 --seed 3 contacts.csv truth.ply)
run_tool("${FUSE}" 0 contacts.csv cloud.ply)
file(WRITE "${WORK_DIR}/image.csv" "")
foreach(r RANGE 1 16)
  set(row "")
  foreach(c RANGE 1 16)
    math(EXPR v "(${r} - 8) * (${r} - 8) + (${c} - 8) * (${c} - 8)")
    if(v LESS 20)
      set(v 200)
    else()
      set(v 0)
    endif()
    if(c EQUAL 1)
      set(row "${v}")
    else()
      string(APPEND row ",${v}")
    endif()
  endforeach()
  file(APPEND "${WORK_DIR}/image.csv" "${row}\n")
endforeach()
file(WRITE "${WORK_DIR}/data.libsvm" "1 1:1 2:0.5\n-1 1:-1 2:-0.25\n1 1:0.8 2:0.9\n-1 1:-0.7 2:0.1\n")
run_tool("${TRAIN}" 0 -q data.libsvm data.model)

# Standard output that cannot be written.
function(expect_stdout_loss tool)
  execute_process(COMMAND "${tool}" ${ARGN} WORKING_DIRECTORY "${WORK_DIR}"
                  RESULT_VARIABLE rc OUTPUT_FILE /dev/full ERROR_VARIABLE err)
  if(NOT rc EQUAL 1 OR NOT err MATCHES "cannot write standard output")
    message(FATAL_ERROR "${tool} ${ARGN} >/dev/full: exit ${rc}, expected 1 and "
                        "'cannot write standard output'\n${err}")
  endif()
endfunction()

# A file output that cannot be written: `file` holds "previous" before and after, and the error
# names `named` (the file itself unless NAMED is set).
function(expect_file_loss file tool)
  if(NOT DEFINED NAMED)
    set(NAMED "${file}")
  endif()
  file(WRITE "${WORK_DIR}/${file}" "previous\n")
  execute_process(COMMAND sh -c "trap '' XFSZ; ulimit -f 0; exec \"$0\" \"$@\"" "${tool}" ${ARGN}
                  WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc OUTPUT_VARIABLE out
                  ERROR_VARIABLE err)
  if(NOT rc EQUAL 1)
    message(FATAL_ERROR "${tool} ${ARGN} on a full disk: exit ${rc}, expected 1\n${out}\n${err}")
  endif()
  expect("${err}" "${NAMED}")
  expect("${err}" "File too large")
  file(READ "${WORK_DIR}/${file}" kept)
  if(NOT kept STREQUAL "previous\n")
    message(FATAL_ERROR "${tool} ${ARGN}: the previous ${file} was not kept:\n${kept}")
  endif()
  get_filename_component(dir "${WORK_DIR}/${file}" DIRECTORY)
  file(GLOB left "${dir}/.*.tmp.*")
  if(left)
    message(FATAL_ERROR "${tool} ${ARGN}: temporary files left behind: ${left}")
  endif()
endfunction()

expect_stdout_loss("${SIMULATE}" --contacts 500 --seed 1 c2.csv)
expect_file_loss(c3.csv "${SIMULATE}" --contacts 500 --seed 1 c3.csv)
# The contacts are written first, so they fail first.
set(NAMED c4.csv)
expect_file_loss(t3.ply "${SIMULATE}" --contacts 500 --seed 1 c4.csv t3.ply)
unset(NAMED)

expect_stdout_loss("${FUSE}" contacts.csv cloud2.ply)
expect_file_loss(cloud3.ply "${FUSE}" contacts.csv cloud3.ply)

expect_stdout_loss("${ICP}" cloud.ply truth.ply)
expect_file_loss(aligned.ply "${ICP}" cloud.ply truth.ply -o aligned.ply)

file(MAKE_DIRECTORY "${WORK_DIR}/models")
file(COPY "${WORK_DIR}/truth.ply" DESTINATION "${WORK_DIR}/models")
expect_stdout_loss("${RECOGNIZE}" --starts 0 cloud.ply models)

expect_stdout_loss("${DESCRIBE}" image.csv)
expect_stdout_loss("${DESCRIBE}" --format json image.csv)
expect_file_loss(desc.csv "${DESCRIBE}" -o desc.csv image.csv)
# Bad input leaves an existing output alone (the output is written only at the end).
file(WRITE "${WORK_DIR}/keep.csv" "previous\n")
file(WRITE "${WORK_DIR}/bad.csv" "1,2\n3\n")
run_tool("${DESCRIBE}" 1 -o keep.csv bad.csv)
file(READ "${WORK_DIR}/keep.csv" kept)
if(NOT kept STREQUAL "previous\n")
  message(FATAL_ERROR "taxel-describe on bad input emptied its output file")
endif()

expect_stdout_loss("${TRAIN}" data.libsvm data2.model)
expect_file_loss(data3.model "${TRAIN}" -q data.libsvm data3.model)

expect_stdout_loss("${PREDICT}" data.libsvm data.model pred2.txt)
expect_file_loss(pred3.txt "${PREDICT}" -q data.libsvm data.model pred3.txt)

file(MAKE_DIRECTORY "${WORK_DIR}/demo")
# The demo writes many files; the first that fails ends it (index.html comes last).
set(NAMED "demo/")
expect_file_loss(demo/index.html "${DEMO}" --quick demo)
