# SPDX-License-Identifier: MIT
# Command-line contract of taxel-optical on frames rendered by 09_optical_sensor: calibrate
# (given background, or the median of a folder of presses), depth with its mask and contacts,
# JSON summaries, and one-line errors with nothing written on bad input.
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

run_tool("${TOOL}" 0 --help)
expect("${out}" "usage: taxel-optical calibrate")
expect_version("${TOOL}" taxel-optical)

run_tool("${EXAMPLE}" 0 --quick --out "${WORK_DIR}/frames")
if(HAVE_PNG)
  set(ext png)
else()
  set(ext npy)
endif()
set(f "${WORK_DIR}/frames")
file(GLOB presses "${f}/press_*.${ext}")
list(LENGTH presses n)
if(NOT n EQUAL 6)
  message(FATAL_ERROR "09_optical_sensor wrote ${n} presses, expected 6")
endif()

# Calibrate with the background given: a JSON file and a JSON summary.
run_tool("${TOOL}" 0 calibrate --ball-radius 2 --mm-per-pixel 0.0634 --background
         "${f}/background.${ext}" ${presses} -o cal.json --format json)
json_length(circles "${out}" circles)
json_get(heldout "${out}" heldout_gradient_rms)
json_get(radius "${out}" ball_radius_m)
json_get(r0 "${out}" circles 0 radius_px)
if(NOT circles EQUAL 6 OR heldout GREATER 0.2 OR NOT radius EQUAL 0.002 OR r0 LESS 10)
  message(FATAL_ERROR "calibrate: ${circles} circles, held-out ${heldout}, radius ${radius}, "
                      "first circle ${r0} px")
endif()
file(READ "${WORK_DIR}/cal.json" cal)
json_get(format "${cal}" format)
json_get(rows "${cal}" rows)
if(NOT format STREQUAL "taxel optical calibration" OR NOT rows EQUAL 240)
  message(FATAL_ERROR "cal.json: format '${format}', rows ${rows}")
endif()
# The ball radius with a unit, a bare value in metres, and a binary calibration file.
run_tool("${TOOL}" 0 calibrate --ball-radius 0.002 --mm-per-pixel 0.0634 --background
         "${f}/background.${ext}" ${presses} -o cal.txcal)
expect("${out}" "ball_radius_m 0.002")
file(READ "${WORK_DIR}/cal.txcal" head LIMIT 6 HEX)
if(NOT head STREQUAL "54584f43414c")  # "TXOCAL"
  message(FATAL_ERROR "cal.txcal does not start with TXOCAL")
endif()

# A folder of presses and no background: the per-pixel median of the presses.
file(MAKE_DIRECTORY "${WORK_DIR}/presses")
file(COPY ${presses} DESTINATION "${WORK_DIR}/presses")
run_tool("${TOOL}" 0 calibrate --ball-radius 2mm --mm-per-pixel 0.0634 presses -o median.json
         --format json)
json_get(bg "${out}" background)
json_get(heldout_median "${out}" heldout_gradient_rms)
expect("${bg}" "^median of 6 presses$")
if(heldout_median GREATER 0.25)
  message(FATAL_ERROR "calibrate on the median background: held-out ${heldout_median}")
endif()

# Depth of the held-out press: float64 heights in metres, a uint8 mask, contacts.
run_tool("${TOOL}" 0 depth --calibration cal.json "${f}/held_out.${ext}" -o h.npy --mask m.npy
         --contacts c.csv --format json)
json_get(touched "${out}" touched_pixels)
json_get(peak "${out}" max_height_m)
json_get(contacts "${out}" contacts)
if(touched LESS 500 OR peak LESS 0.0002 OR peak GREATER 0.0009 OR contacts LESS 20)
  message(FATAL_ERROR "depth: ${touched} touched pixels, peak ${peak} m, ${contacts} contacts")
endif()
file(READ "${WORK_DIR}/h.npy" hhead OFFSET 10 LIMIT 60)
expect("${hhead}" "'descr': '<f8', 'fortran_order': False, 'shape': \\(240, 320\\)")
file(SIZE "${WORK_DIR}/h.npy" hsize)
file(SIZE "${WORK_DIR}/m.npy" msize)
if(NOT hsize EQUAL 614528 OR NOT msize EQUAL 76928)  # 128-byte headers, 8 and 1 byte values
  message(FATAL_ERROR "h.npy is ${hsize} bytes, m.npy ${msize}")
endif()
file(READ "${WORK_DIR}/m.npy" mhead OFFSET 10 LIMIT 60)
expect("${mhead}" "'descr': '\\|u1'")
file(STRINGS "${WORK_DIR}/c.csv" csv LIMIT_COUNT 1)
expect("${csv}" "x,y,z")
# The binary calibration gives the same heights.
run_tool("${TOOL}" 0 depth --calibration cal.txcal "${f}/held_out.${ext}" -o h2.npy)
file(SHA256 "${WORK_DIR}/h.npy" a)
file(SHA256 "${WORK_DIR}/h2.npy" b)
if(NOT a STREQUAL b)
  message(FATAL_ERROR "depth: cal.json and cal.txcal give different heights")
endif()

# Marker tracking: the gel slides 0.6 px per frame; every dot is followed.
file(GLOB slides "${f}/slide_*.${ext}")
run_tool("${TOOL}" 0 track ${slides} -o tracks.csv --format json)
json_get(ref_dots "${out}" reference_dots)
json_length(nframes "${out}" frames)
json_get(shift "${out}" frames 4 mean_displacement_px)
json_get(lost "${out}" frames 4 lost)
if(NOT nframes EQUAL 5 OR ref_dots LESS 100 OR shift LESS 2.8 OR shift GREATER 3.2 OR lost GREATER 2)
  message(FATAL_ERROR "track: ${nframes} frames, ${ref_dots} dots, last shift ${shift} px, "
                      "${lost} lost")
endif()
file(STRINGS "${WORK_DIR}/tracks.csv" tracks LIMIT_COUNT 2)
expect("${tracks}" "^frame,track,x0,y0,x,y,dx,dy,seen;1,0,")

# Bad usage: exit 2, one line, nothing written.
foreach(args
    "calibrate"
    "nonsense"
    "calibrate;--ball-radius;abc;--mm-per-pixel;0.06;x.png;-o;bad.json"
    "calibrate;--ball-radius;2;x.png;-o;bad.json"
    "calibrate;--ball-radius;2;--mm-per-pixel;0.06;x.png"
    "depth;--calibration;cal.json;--ball-radius;2;x.png;-o;bad.npy"
    "depth;--calibration;cal.json;x.png;-o;-"
    "depth;--calibration;cal.json;${f}/held_out.${ext};-o;cal.json"
    "depth;--calibration;cal.json;${f}/held_out.${ext};-o;bad.npy;--mask;bad.npy"
    "track;${f}/slide_00.${ext}"
    "track;--calibration;cal.json;${f}/slide_00.${ext};${f}/slide_01.${ext}")
  run_tool("${TOOL}" 2 ${args})
  expect_one_line("${err}")
  expect("${err}" "^taxel-optical: ")
endforeach()

# Bad data: exit 1, one line naming the problem, no output file.
file(WRITE "${WORK_DIR}/notes.txt" "not a frame\n")
run_tool("${TOOL}" 1 depth --calibration cal.json notes.txt -o bad.npy)
expect("${err}" "notes.txt: not a PNG, JPEG or NPY frame")
run_tool("${TOOL}" 1 depth --calibration notes.txt "${f}/held_out.${ext}" -o bad.npy)
expect("${err}" "notes.txt.*not a taxel optical calibration")
run_tool("${TOOL}" 1 depth --calibration cal.json "${f}/dark.${ext}" -o bad.npy)
expect("${err}" "no gel in view")
# A press without contact (the background itself).
run_tool("${TOOL}" 1 calibrate --ball-radius 2 --mm-per-pixel 0.0634 --background
         "${f}/background.${ext}" "${f}/background.${ext}" ${presses} -o bad.json)
expect("${err}" "press 0: find_contact_circle: no contact")
expect_one_line("${err}")
# Circles given for review: the count must match.
file(WRITE "${WORK_DIR}/circles.txt" "# cx cy radius\n100, 100, 20\n")
run_tool("${TOOL}" 1 calibrate --ball-radius 2 --mm-per-pixel 0.0634 --background
         "${f}/background.${ext}" ${presses} --circles circles.txt -o bad.json)
expect("${err}" "circles.txt has 1 circles for 6 presses")
foreach(bad bad.json bad.npy)
  if(EXISTS "${WORK_DIR}/${bad}")
    message(FATAL_ERROR "a failed run wrote ${bad}")
  endif()
endforeach()
