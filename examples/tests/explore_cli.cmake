# SPDX-License-Identifier: MIT
# Command-line contract of taxel-explore: a short active exploration that improves touch by
# touch, its meshes with per-vertex sigma, recognition among a small library, and one-line
# errors (exit 2 for options, 1 for files) on bad input.
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

run_tool("${TOOL}" 0 --help)
expect("${out}" "usage: taxel-explore")
expect_version("${TOOL}" taxel-explore)

# Eight active touches of a box: JSON per touch; the estimate gets closer, wider and surer.
run_tool("${TOOL}" 0 --shape box --touches 8 --seed 3 --format json --out meshes)
json_length(n "${out}" touches)
if(NOT n EQUAL 8)
  message(FATAL_ERROR "expected 8 touches, got ${n}:\n${out}")
endif()
json_get(first_rms "${out}" touches 0 surface_rms)
json_get(last_rms "${out}" touches 7 surface_rms)
json_get(first_cov "${out}" touches 0 coverage)
json_get(last_cov "${out}" touches 7 coverage)
json_get(first_std "${out}" touches 0 mean_std)
json_get(last_std "${out}" touches 7 mean_std)
json_get(contacts "${out}" touches 7 contacts)
json_get(k "${out}" touches 7 touch)
if(NOT last_rms LESS first_rms OR NOT last_cov GREATER first_cov OR NOT last_std LESS first_std
   OR NOT contacts GREATER 1000 OR NOT k EQUAL 8)
  message(FATAL_ERROR "no progress over 8 touches: rms ${first_rms} -> ${last_rms}, coverage "
                      "${first_cov} -> ${last_cov}, std ${first_std} -> ${last_std}, "
                      "${contacts} contacts")
endif()
foreach(t 1 8)
  file(READ "${WORK_DIR}/meshes/touch_${t}.ply" head LIMIT 400)
  expect("${head}" "property double sigma")
  expect("${head}" "element face [1-9]")
endforeach()

# The same seed gives the same table; CSV and text carry the same columns.
run_tool("${TOOL}" 0 --shape box --touches 2 --seed 3 --format csv --policy random)
expect("${out}" "^touch,contacts,surface_rms,surface_signed,coverage,mean_std\n1,")
run_tool("${TOOL}" 0 --shape sphere --touches 2 --policy scripted)
expect("${out}" "touch contacts +surface_rms_mm +surface_signed_mm +coverage +mean_std_mm\n +1 ")

# Recognition among three models (the true surfaces taxel-simulate samples).
file(MAKE_DIRECTORY "${WORK_DIR}/lib")
foreach(model "sphere;0.03" "box;0.04,0.03,0.02" "cylinder;0.025,0.04")
  list(GET model 0 name)
  list(GET model 1 size)
  run_tool("${SIMULATE}" 0 --shape ${name} --size ${size} --exploration palpation --touches 1
           --contacts 0 --truth-points 4000 c.csv lib/${name}.ply)
endforeach()
run_tool("${TOOL}" 0 --shape box --touches 5 --seed 2 --library lib --format json)
json_get(top "${out}" touches 4 top1)
json_get(p "${out}" touches 4 probability)
if(NOT top STREQUAL "box" OR p LESS 0.5)
  message(FATAL_ERROR "after 5 touches of a box: top1 ${top} with probability ${p}\n${out}")
endif()

# Bad input: one line, exit 2 for options, 1 for files; nothing written.
foreach(bad "--touches;0" "--shape;cube" "--policy;greedy" "--grid;0" "--frobnicate"
            "--shape;box;--mesh;x.ply" "stray.ply" "--size;-1")
  run_tool("${TOOL}" 2 ${bad})
  expect_one_line("${err}")
endforeach()
run_tool("${TOOL}" 2 --shape box --size 0.04)
expect("${err}" "--size for a box takes 3 length")
file(WRITE "${WORK_DIR}/bad.ply" "ply\nformat ascii 1.0\nelement vertex 2\n")
foreach(bad "--mesh;missing.ply" "--mesh;bad.ply" "--library;missing" "--library;meshes/touch_1.ply"
            "--out;bad.ply")
  run_tool("${TOOL}" 1 --touches 1 ${bad})
  expect_one_line("${err}")
endforeach()
file(MAKE_DIRECTORY "${WORK_DIR}/empty")
run_tool("${TOOL}" 1 --touches 1 --library empty)
expect("${err}" "no .ply files")
# A lost standard output is exit 1.
execute_process(COMMAND "${TOOL}" --touches 1 OUTPUT_FILE /dev/full RESULT_VARIABLE rc
                ERROR_VARIABLE err)
if(NOT rc EQUAL 1)
  message(FATAL_ERROR "stdout on /dev/full: exit ${rc}, expected 1\n${err}")
endif()
