# SPDX-License-Identifier: MIT
# Lost writes are errors, and outputs are written whole or not at all, for every tool:
# - standard output on /dev/full: exit 1 with "cannot write standard output";
# - a file output on a "full disk" (the file size limit at 0, as `ulimit -f 0`, with SIGXFSZ
#   ignored, so every write to a regular file fails with EFBIG): exit 1 naming the file, the
#   previous file unchanged, no temporary file left beside it;
# - an output that is one of the run's inputs, or another of its outputs: exit 2, nothing
#   written, the input unchanged.
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

# An output that is an input (by name, another relative path, or a link), or another output:
# refused before anything is read or written, the input as it was.
function(expect_refused tool pattern)
  file(GLOB before RELATIVE "${WORK_DIR}" "${WORK_DIR}/*")
  foreach(f IN LISTS before)
    if(NOT IS_DIRECTORY "${WORK_DIR}/${f}")
      file(SHA256 "${WORK_DIR}/${f}" sum_${f})
    endif()
  endforeach()
  run_tool("${tool}" 2 ${ARGN})
  expect("${err}" "${pattern}")
  expect_one_line("${err}")
  file(GLOB after RELATIVE "${WORK_DIR}" "${WORK_DIR}/*")
  if(NOT after STREQUAL before)
    message(FATAL_ERROR "${tool} ${ARGN}: files appeared or vanished:\n${before}\n${after}")
  endif()
  foreach(f IN LISTS before)
    if(NOT IS_DIRECTORY "${WORK_DIR}/${f}")
      file(SHA256 "${WORK_DIR}/${f}" now)
      if(NOT now STREQUAL sum_${f})
        message(FATAL_ERROR "${tool} ${ARGN}: ${f} changed")
      endif()
    endif()
  endforeach()
endfunction()

set(is_input "is the input '")
expect_refused("${FUSE}" "${is_input}contacts.csv'" contacts.csv contacts.csv)
expect_refused("${FUSE}" "${is_input}contacts.csv'" contacts.csv ./contacts.csv)
file(CREATE_LINK contacts.csv "${WORK_DIR}/contacts_link.csv" SYMBOLIC)
expect_refused("${FUSE}" "${is_input}contacts.csv'" contacts.csv contacts_link.csv)
run_tool("${SIMULATE}" 0 --contacts 500 --seed 2 --readings r.npy --poses p.csv c5.csv)
expect_refused("${FUSE}" "${is_input}p.csv'" --readings r.npy --poses p.csv p.csv)
expect_refused("${FUSE}" "${is_input}r.npy'" --readings r.npy --poses p.csv r.npy)
expect_refused("${ICP}" "${is_input}truth.ply'" cloud.ply truth.ply -o truth.ply)
expect_refused("${DESCRIBE}" "${is_input}image.csv'" -o image.csv image.csv)
expect_refused("${TRAIN}" "${is_input}data.libsvm'" -q data.libsvm data.libsvm)
expect_refused("${PREDICT}" "${is_input}data.model'" data.libsvm data.model data.model)
set(same "are the same file")
expect_refused("${SIMULATE}" "${same}" --contacts 500 c6.csv c6.csv)
expect_refused("${SIMULATE}" "${same}" --contacts 500 --readings r6.npy --poses r6.npy c6.csv)
expect_refused("${SIMULATE}" "${same}" --contacts 500 --poses c6.csv c6.csv)

# Outputs that belong together are written as a set: when one of them cannot be written (its
# folder is missing; a disk that fills up part-way fails the same way, at the writes), none
# replaces its previous version, so new readings never sit beside old poses.
file(WRITE "${WORK_DIR}/set_readings.npy" "previous\n")
file(WRITE "${WORK_DIR}/set_contacts.csv" "previous\n")
run_tool("${SIMULATE}" 1 --contacts 500 --seed 4 --readings set_readings.npy
         --poses no_such_folder/p.csv set_contacts.csv)
expect("${err}" "no_such_folder/p.csv")
foreach(f set_readings.npy set_contacts.csv)
  file(READ "${WORK_DIR}/${f}" kept)
  if(NOT kept STREQUAL "previous\n")
    message(FATAL_ERROR "taxel-simulate replaced ${f} although the set failed")
  endif()
endforeach()
file(GLOB left "${WORK_DIR}/.set_*.tmp.*")
if(left)
  message(FATAL_ERROR "taxel-simulate left temporary files behind: ${left}")
endif()
# Other tools' outputs named by the file they open: standard input as /dev/stdin.
foreach(alias /dev/stdin /dev/fd/0)
  execute_process(COMMAND "${ICP}" - truth.ply -o ${alias} WORKING_DIRECTORY "${WORK_DIR}"
                  INPUT_FILE "${WORK_DIR}/cloud.ply" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "is the input '<stdin>'")
    message(FATAL_ERROR "taxel-icp -o ${alias} with the source on standard input: exit ${rc}\n${err}")
  endif()
  execute_process(COMMAND "${DESCRIBE}" - -o ${alias} WORKING_DIRECTORY "${WORK_DIR}"
                  INPUT_FILE "${WORK_DIR}/image.csv" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "is the input '<stdin>'")
    message(FATAL_ERROR "taxel-describe -o ${alias}: exit ${rc}\n${err}")
  endif()
  execute_process(COMMAND "${PREDICT}" - data.model ${alias} WORKING_DIRECTORY "${WORK_DIR}"
                  INPUT_FILE "${WORK_DIR}/data.libsvm" RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "is the input '<stdin>'")
    message(FATAL_ERROR "taxel-predict - data.model ${alias}: exit ${rc}\n${err}")
  endif()
endforeach()
