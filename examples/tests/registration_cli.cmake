# SPDX-License-Identifier: MIT
# Command-line contract of taxel-icp and taxel-recognize on the clouds and models that
# 03_icp_align and 04_recognize_objects write: alignment recovers the pose, recognition names the
# object, bad input gives a one-line error and a non-zero exit.
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

run_tool("${ALIGN}" 0 --quick --out align)
expect("${out}" "point-to-plane +ok")
run_tool("${RECOGNIZE_EXAMPLE}" 0 --quick --out rec)
expect("${out}" "top-1 [0-9]+ / 7")

run_tool("${ICP}" 0 --help)
expect("${out}" "usage: taxel-icp")
# The cloud in its sensor frame against the model: the printed transform maps it onto the box,
# so aligning its output again changes nothing.
run_tool("${ICP}" 0 --max-distance 0.05 --max-iterations 200 -o aligned.ply align/cloud_start.ply
         align/model.ply)
expect("${out}" "^[-0-9.e]+ [-0-9.e]+ [-0-9.e]+ [-0-9.e]+\n")
expect("${out}" "\n0 0 0 1\nrmse 0\\.00[0-2][0-9]*\nfitness 1\\.0+\niterations [0-9]+\nstatus ok")
run_tool("${ICP}" 0 --method point-to-point --kernel huber --kernel-scale 0.001 aligned.ply
         align/model.ply)
expect("${out}" "^(1|0\\.99[0-9]*) [-0-9.e]+ [-0-9.e]+ [-0-9.e]+\n")  # near identity
expect("${out}" "status (ok|not_converged)")
run_tool("${ICP}" 0 --init "1 0 0 0.001 0 1 0 0 0 0 1 0 0 0 0 1" aligned.ply align/model.ply)
expect("${out}" "status ok")
expect_version("${ICP}" taxel-icp)
# JSON (parsed) and CSV; the source from standard input and the aligned cloud to standard
# output (the result then on standard error) give the same numbers as files.
run_tool("${ICP}" 0 --format=json --max-distance=5cm --max-iterations 200 align/cloud_start.ply
         align/model.ply)
json_get(status "${out}" status)
json_get(t15 "${out}" transform 15)
json_get(angle "${out}" angle)
if(NOT status STREQUAL "ok" OR NOT t15 EQUAL 1 OR NOT angle GREATER 0)
  message(FATAL_ERROR "taxel-icp --format json:\n${out}")
endif()
set(icp_json "${out}")
run_tool_stdin("${ICP}" 0 align/cloud_start.ply --format json --max-distance 50mm
               --max-iterations 200 -o - - align/model.ply)
expect("${out}" "^ply\n")
if(NOT err STREQUAL icp_json)
  message(FATAL_ERROR "taxel-icp - -o -: the result differs from the files':\n${err}")
endif()
run_tool("${ICP}" 0 --format csv aligned.ply align/model.ply)
expect("${out}" "^transform.0,transform.1,[^\n]*,translation.0,translation.1,translation.2,axis.0,axis.1,axis.2,angle,rmse,fitness,iterations,status,skipped\n[-0-9.e]+,[^\n]*,ok,0\n$")
run_tool("${ICP}" 2 - - )
expect("${err}" "only one input can be standard input")
run_tool("${ICP}" 2 --max-distance 5parsecs aligned.ply align/model.ply)
expect("${err}" "--max-distance: '5parsecs' is not a length")

run_tool("${ICP}" 2 --method sideways a.ply b.ply)
expect("${err}" "--method must be")
run_tool("${ICP}" 2 --init "1 2 3" a.ply b.ply)
expect("${err}" "--init needs 16 numbers, got 3")
run_tool("${ICP}" 2 --trim 1.5 aligned.ply align/model.ply)
expect("${err}" "trim_fraction")
run_tool("${ICP}" 2 only-one.ply)
expect("${err}" "expected SOURCE.ply and TARGET.ply")
file(WRITE "${WORK_DIR}/broken.ply" "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
     "property float y\nproperty float z\nend_header\n0 0 0\n1 1\n")
run_tool("${ICP}" 1 broken.ply align/model.ply)
expect("${err}" "broken.ply:9: line ends before z")
expect_one_line("${err}")
run_tool("${ICP}" 1 missing.ply align/model.ply)
expect("${err}" "cannot open")

run_tool("${RECOGNIZE}" 0 --threads 1 rec/clouds/cube-50.ply rec/models)
set(serial "${out}")
run_tool("${RECOGNIZE}" 0 --threads=3 rec/clouds/cube-50.ply rec/models)
if(NOT out STREQUAL serial)
  message(FATAL_ERROR "--threads 3 changed the answer:\n${out}\nvs\n${serial}")
endif()
run_tool("${RECOGNIZE}" 2 --threads x rec/clouds/cube-50.ply rec/models)
expect("${err}" "--threads: 'x' is not")
run_tool("${RECOGNIZE}" 0 rec/clouds/cube-50.ply rec/models)
expect("${out}" "^rank +model")
expect("${out}" "\n1 +cube-50 ")
expect("${out}" "best: cube-50 \\(margin [0-9.]+ mm\\)")
run_tool("${RECOGNIZE}" 0 --format json rec/clouds/sphere-25.ply rec/models/sphere-25.ply
         rec/models/sphere-40.ply rec/models/cylinder-20x60.ply)
json_get(best "${out}" best)
json_get(first "${out}" ranking 0 model)
json_length(n "${out}" ranking)
if(NOT best STREQUAL "sphere-25" OR NOT first STREQUAL "sphere-25" OR NOT n EQUAL 3)
  message(FATAL_ERROR "taxel-recognize --format json:\n${out}")
endif()
expect_version("${RECOGNIZE}" taxel-recognize)
run_tool_stdin("${RECOGNIZE}" 0 rec/clouds/sphere-25.ply --format csv --gate=1cm -
               rec/models/sphere-25.ply rec/models/sphere-40.ply)
expect("${out}" "^rank,model,score,exact,rmse,fitness,transform.0,")
expect("${out}" ",best,unknown,margin\n1,sphere-25,[^\n]*,sphere-25,false,[0-9.e-]+\n2,sphere-40,")
run_tool("${RECOGNIZE}" 2 rec/clouds/sphere-25.ply -)
expect("${err}" "only CLOUD can be standard input")
run_tool("${RECOGNIZE}" 0 --unknown 0.0001 rec/clouds/cube-50.ply rec/models)
expect("${out}" "best: unknown")
run_tool("${RECOGNIZE}" 2 --starts 40 rec/clouds/cube-50.ply rec/models)
expect("${err}" "rotation_starts")
run_tool("${RECOGNIZE}" 1 broken.ply rec/models)
expect("${err}" "broken.ply:9")
expect_one_line("${err}")
file(MAKE_DIRECTORY "${WORK_DIR}/empty")
run_tool("${RECOGNIZE}" 1 rec/clouds/cube-50.ply empty)
expect("${err}" "no .ply files")

# Hostile models: coordinates whose extent overflows (this used to hang) and a property named
# twice are bad data (exit 1), refused at once; float coordinates near the float limit (an int
# overflow once aborted) are a legal, if useless, model.
set(head "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nend_header\n")
file(WRITE "${WORK_DIR}/wide.ply" "${head}-1e308 0 0\n1e308 0 0\n0 1 0\n0 0 1\n")
run_tool("${ICP}" 1 rec/clouds/cube-50.ply wide.ply)
expect("${err}" "wide.ply: UniformGrid: the points span")
expect_one_line("${err}")
file(MAKE_DIRECTORY "${WORK_DIR}/wide_models")
file(COPY "${WORK_DIR}/wide.ply" DESTINATION "${WORK_DIR}/wide_models")
run_tool("${RECOGNIZE}" 1 rec/clouds/cube-50.ply wide_models)
expect("${err}" "wide.ply: UniformGrid")
string(REPLACE "double" "float" fhead "${head}")
file(WRITE "${WORK_DIR}/huge_float.ply" "${fhead}-1e38 0 0\n1e38 0 0\n0 1e38 0\n0 0 -1e38\n")
run_tool("${RECOGNIZE}" 0 rec/clouds/cube-50.ply huge_float.ply)
expect("${out}" "best: unknown")
file(WRITE "${WORK_DIR}/twice.ply" "${head}property double x\n")
string(REPLACE "property double z\nend_header\nproperty double x\n"
       "property double z\nproperty double x\nend_header\n1 2 3 4\n" twice "${head}property double x\n")
file(WRITE "${WORK_DIR}/twice.ply" "${twice}")
run_tool("${ICP}" 1 rec/clouds/cube-50.ply twice.ply)
expect("${err}" "twice.ply:7: element 'vertex' has two properties named 'x'")

# Millimetre clouds: said, with the fix, by taxel-icp and taxel-recognize; --scale 0.001 fixes it.
set(mm "ply\nformat ascii 1.0\nelement vertex 400\nproperty double x\nproperty double y\nproperty double z\nend_header\n")
foreach(i RANGE 0 19)
  foreach(j RANGE 0 19)
    math(EXPR z "(${i} * ${j}) % 3")
    string(APPEND mm "${i} ${j} ${z}\n")
  endforeach()
endforeach()
file(WRITE "${WORK_DIR}/mm.ply" "${mm}")
run_tool("${ICP}" 0 mm.ply mm.ply)
expect("${err}" "mm.ply spans 19 along one axis: its coordinates look like millimetres")
run_tool("${ICP}" 0 --scale 0.001 mm.ply mm.ply)
if(err MATCHES "millimetres")
  message(FATAL_ERROR "taxel-icp --scale 0.001 still warns:\n${err}")
endif()
run_tool("${RECOGNIZE}" 0 --starts 0 mm.ply mm.ply)
expect("${err}" "--scale 0.001")

# Meshes: a PLY with faces stands for its surface. 04_recognize_objects wrote the same seven
# objects as meshes of very uneven vertex density (12 triangles for a box, 2 562 vertices for a
# sphere): recognised by their surfaces, the box cloud is the box.
run_tool("${RECOGNIZE}" 0 rec/clouds/box-80x60x40.ply rec/meshes)
expect("${out}" "best: box-80x60x40 ")
expect("${err}" "box-80x60x40.ply: 12 triangles: 20800 points sampled area-uniformly at 0.001")
expect("${err}" "sphere-40.ply: 5120 triangles: ")
run_tool("${RECOGNIZE}" 0 rec/clouds/sphere-25.ply rec/meshes)
expect("${out}" "best: sphere-25 ")
run_tool("${ICP}" 0 rec/clouds/cube-50.ply rec/meshes/cube-50.ply)
expect("${err}" "cube-50.ply: 12 triangles: 1500[01] points sampled")
expect("${out}" "\nstatus [a-z_]+\n")
# The same meshes in millimetres: the warning with the fix, then a clear refusal (the surface
# would need billions of points at 1 mm spacing in metres), never a crash or a silent answer.
run_tool("${RECOGNIZE}" 1 --scale 1000 rec/clouds/box-80x60x40.ply rec/meshes)
expect("${err}" "look like millimetres")
expect("${err}" "needs [0-9.e+]+ points, more than 4194304")
run_tool("${RECOGNIZE}" 2 --mesh-spacing -1 rec/clouds/box-80x60x40.ply rec/meshes)
expect("${err}" "--mesh-spacing")

# The recognised pose: T_model_cloud as 4x4, translation and axis-angle. Fed to taxel-icp as
# its initial transform, it already maps the cloud onto the model (one iteration, low RMSE).
run_tool("${RECOGNIZE}" 0 rec/clouds/box-80x60x40.ply rec/models)
expect("${out}" "best: box-80x60x40 ")
string(REGEX MATCH "pose of box-80x60x40 \\(T_model_cloud\\):\n([^\n]+)\n([^\n]+)\n([^\n]+)\n([^\n]+)\n"
       m "${out}")
if(NOT m)
  message(FATAL_ERROR "no pose in:\n${out}")
endif()
set(pose "${CMAKE_MATCH_1} ${CMAKE_MATCH_2} ${CMAKE_MATCH_3} ${CMAKE_MATCH_4}")
expect("${out}" "\ntranslation [-0-9.e]+ [-0-9.e]+ [-0-9.e]+\naxis [-0-9.e]+ [-0-9.e]+ [-0-9.e]+\nangle [0-9.e]+ rad")
run_tool("${ICP}" 0 --init "${pose}" --max-iterations 1 rec/clouds/box-80x60x40.ply
         rec/models/box-80x60x40.ply)
expect("${out}" "\nrmse 0\\.00[01][0-9]*\n")
run_tool("${RECOGNIZE}" 0 --format json --starts 4 rec/clouds/box-80x60x40.ply rec/models)
json_length(n "${out}" ranking 0 transform)
json_get(tz "${out}" ranking 0 translation 2)
json_get(ax "${out}" ranking 0 axis 0)
if(NOT n EQUAL 16)
  message(FATAL_ERROR "taxel-recognize --format json: the transform has ${n} numbers")
endif()
