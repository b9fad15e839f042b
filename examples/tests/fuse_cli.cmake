# SPDX-License-Identifier: MIT
# Command-line contract of taxel-fuse: contacts CSV in, fused PLY out; counts per outcome;
# policies and indexes by option; one-line errors that say where.
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

run_tool("${TOOL}" 0 --help)
expect("${out}" "usage: taxel-fuse")

# 20 places 10 mm apart, each touched three times within 0.2 mm, plus one contact with a NaN
# covariance.
set(csv "# three touches per place\ntime,x,y,z,cxx,cxy,cxz,cyy,cyz,czz\n")
foreach(i RANGE 10 29)
  foreach(k RANGE 2)
    string(APPEND csv "0.00${k},0.${i}0${k},0.0,0.0,1e-6,0,0,1e-6,0,1e-6\n")
  endforeach()
endforeach()
string(APPEND csv "0.5,0.9,0.9,0.9,nan,0,0,1e-6,0,1e-6\n")
file(WRITE "${WORK_DIR}/contacts.csv" "${csv}")

foreach(index voxel-hash kd-tree brute-force)
  run_tool("${TOOL}" 0 --index ${index} contacts.csv cloud-${index}.ply)
  expect("${out}" "contacts 61\nadded 20\nfused 40\nrejected 1 \\(covariance is not finite 1\\)\npoints 20\n")
endforeach()
file(READ "${WORK_DIR}/cloud-voxel-hash.ply" head LIMIT 400)
expect("${head}" "element vertex 20\n")
expect("${head}" "property double observations\n")
run_tool("${TOOL}" 0 --policy raw --ascii contacts.csv raw.ply)
expect("${out}" "points 60\n")
file(READ "${WORK_DIR}/raw.ply" raw)
expect("${raw}" "format ascii 1.0")
run_tool("${TOOL}" 0 --policy average --radius 0.0001 contacts.csv avg.ply)
expect("${out}" "points [2-5][0-9]\n")  # a small radius fuses fewer
run_tool("${TOOL}" 0 --gate 11.345 contacts.csv gated.ply)
expect("${out}" "points 20\n")

run_tool("${TOOL}" 2 --policy median contacts.csv x.ply)
expect("${err}" "--policy must be kalman, average or raw")
run_tool("${TOOL}" 2 --radius -1 contacts.csv x.ply)
expect("${err}" "association_radius")
run_tool("${TOOL}" 2 contacts.csv)
expect("${err}" "expected CONTACTS.csv and CLOUD.ply")
file(WRITE "${WORK_DIR}/bad.csv" "x,y,z\n1,2,3\n1,2\n")
run_tool("${TOOL}" 1 bad.csv x.ply)
expect("${err}" "bad.csv:3: row has 2 values")
expect_one_line("${err}")
run_tool("${TOOL}" 1 missing.csv x.ply)
expect("${err}" "cannot open")
