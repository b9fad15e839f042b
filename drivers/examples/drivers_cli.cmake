# SPDX-License-Identifier: MIT
# CLI test of taxel-record and 07_stream_fusion: help, bad options, a session recorded through
# the emulated controller and replayed into fusion, the committed session, and refusals.
include(${CMAKE_CURRENT_LIST_DIR}/../../examples/tests/cli_common.cmake)

run_tool("${RECORD}" 0 --help)
expect("${out}" "usage: taxel-record")
run_tool("${RECORD}" 2 s.session)
expect("${err}" "give exactly one of --serial, --usb, --usb-bus, --emulate")
expect_one_line("${err}")
run_tool("${RECORD}" 2 --usb 12345 s.session)
expect("${err}" "--usb: '12345' is not of the form A:B")
run_tool("${RECORD}" 2 --usb 12g4:0001 s.session)
expect("${err}" "--usb: '12g4:0001' is not of the form A:B")
run_tool("${STREAM}" 2 --usb nope)
expect("${err}" "--usb: 'nope' is not of the form VID:PID \\(hex\\)")
expect_one_line("${err}")
run_tool("${RECORD}" 2 --emulate torus s.session)
expect("${err}" "--emulate takes sphere, cylinder or box")
run_tool("${RECORD}" 2 --serial /dev/null --poses p.csv s.session)
expect("${err}" "--poses needs --emulate")
run_tool("${RECORD}" 1 --serial /nonexistent/ttyDSA s.session)
expect("${err}" "/nonexistent/ttyDSA: cannot open")
expect_one_line("${err}")

# Record a simulated sphere grasp through the emulated controller, then replay it into fusion.
run_tool("${RECORD}" 0 --emulate sphere --grasps 2 --period-ms 5 --poses p.csv s.session)
expect("${out}" "matrices 6\ntactels 504\nframes 60\ndropped 0\ncrc_errors 0\n")
expect("${out}" "\nsession s.session\nposes p.csv\n$")
run_tool("${RECORD}" 0 --emulate sphere --grasps 1 --period-ms 5 --format=json s-json.session)
string(JSON nframes ERROR_VARIABLE json_error GET "${out}" frames)
if(json_error OR NOT nframes GREATER 0)
  message(FATAL_ERROR "taxel-record --format json: ${json_error}\n${out}")
endif()
# --version; the session to standard output with -, the summary (JSON) then on standard error;
# the same conversation as a file of the same recording (the time stamps are wall-clock, and
# how the received bytes are cut into chunks depends on timing: compared is the byte stream).
expect_version("${RECORD}" taxel-record)
run_tool("${RECORD}" 0 --emulate sphere --grasps 1 --period-ms 5 s-file.session)
file(READ "${WORK_DIR}/s-file.session" from_file)
run_tool("${RECORD}" 0 --emulate sphere --grasps 1 --period-ms 5 --format json -)
string(JSON where ERROR_VARIABLE json_error GET "${err}" session)
if(json_error OR NOT where STREQUAL "<stdout>")
  message(FATAL_ERROR "taxel-record --format json -: summary ${json_error}\n${err}")
endif()
string(REGEX REPLACE "\n[0-9.]+ [<>] " "" bytes_file "${from_file}")
string(REGEX REPLACE "\n[0-9.]+ [<>] " "" bytes_stdout "${out}")
string(LENGTH "${bytes_file}" n)
if(n LESS 1000 OR NOT bytes_stdout STREQUAL bytes_file)
  message(FATAL_ERROR "taxel-record - wrote another conversation than to a file")
endif()
run_tool("${RECORD}" 2 --emulate sphere --format=yaml s.session)
expect("${err}" "--format must be one of text,json,csv")
run_tool("${STREAM}" 0 --replay s.session --poses p.csv --out out)
expect("${out}" "frames 60 \\(dropped 0, bad 0, with poses 60\\)")
expect("${out}" "contacts [1-9][0-9]* -> fused points [1-9]")
if(NOT EXISTS "${WORK_DIR}/out/cloud.ply")
  message(FATAL_ERROR "07_stream_fusion wrote no cloud.ply")
endif()
run_tool("${STREAM}" 0 --replay s.session --poses p.csv --per-pad --out out)
expect("${out}" "contacts [1-9][0-9]* -> fused points")

# The committed session (README, demo) still replays.
run_tool("${STREAM}" 0 --replay ${SESSION_DIR}/cylinder_grasp.session
         --poses ${SESSION_DIR}/cylinder_grasp_poses.csv --out out2)
expect("${out}" "frames 78 \\(dropped 0, bad 0, with poses 78\\)")

# Refusals: a malformed session names its line; a host that departs from the recording is caught.
file(WRITE "${WORK_DIR}/bad.session" "taxel-session 1\n0.0 > aaaaaa0g\n")
run_tool("${STREAM}" 1 --replay bad.session)
expect("${err}" "bad.session:2: 'g' at column 14 is not a hex digit")
expect_one_line("${err}")
file(WRITE "${WORK_DIR}/other.session" "taxel-session 1\n0.0 > aaaaaa020000\n")
run_tool("${STREAM}" 1 --replay other.session)
expect("${err}" "differs from the recording at chunk 1, byte 3")
file(WRITE "${WORK_DIR}/bad_poses.csv" "time_ms,matrix,x,y,z,qw,qx,qy,qz\n0,1,0,0,0,1,0,0,0\n")
run_tool("${STREAM}" 1 --replay s.session --poses bad_poses.csv)
expect("${err}" "bad_poses.csv: no pose for matrix 0 at time_ms [0-9]+, where the session's frame reads contact")

# Lost writes are errors: the poses file and the session on a device that is full, standard
# output on /dev/full; a session file that cannot be written keeps the previous one.
run_tool("${RECORD}" 1 --emulate sphere --grasps 1 --period-ms 5 --poses /dev/full s2.session)
expect("${err}" "/dev/full.*No space left on device")
file(WRITE "${WORK_DIR}/keep.session" "previous\n")
execute_process(COMMAND sh -c "trap '' XFSZ; ulimit -f 0; exec \"$0\" \"$@\"" "${RECORD}"
                        --emulate sphere --grasps 1 --period-ms 5 keep.session
                WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "keep.session.*File too large")
  message(FATAL_ERROR "taxel-record on a full disk: exit ${rc}\n${err}")
endif()
file(READ "${WORK_DIR}/keep.session" kept)
if(NOT kept STREQUAL "previous\n")
  message(FATAL_ERROR "taxel-record on a full disk replaced the previous session")
endif()
execute_process(COMMAND "${STREAM}" --replay s.session --out out3 WORKING_DIRECTORY "${WORK_DIR}"
                RESULT_VARIABLE rc OUTPUT_FILE /dev/full ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "cannot write standard output")
  message(FATAL_ERROR "07_stream_fusion >/dev/full: exit ${rc}\n${err}")
endif()
execute_process(COMMAND "${RECORD}" --emulate sphere --grasps 1 --period-ms 5 s3.session
                WORKING_DIRECTORY "${WORK_DIR}" RESULT_VARIABLE rc OUTPUT_FILE /dev/full
                ERROR_VARIABLE err)
if(NOT rc EQUAL 1 OR NOT err MATCHES "cannot write standard output")
  message(FATAL_ERROR "taxel-record >/dev/full: exit ${rc}\n${err}")
endif()

# A damaged session replays what it can and exits 1 with the reason.
file(READ "${WORK_DIR}/s.session" whole)
file(WRITE "${WORK_DIR}/odd.session" "${whole}99.0 < abc\n")
run_tool("${STREAM}" 1 --replay odd.session --out out4)
expect("${out}" "frames 60 ")
expect("${err}" "odd.session:[0-9]+: hex bytes must be .*the cloud holds the frames before it")
