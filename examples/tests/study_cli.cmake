# SPDX-License-Identifier: MIT
# 06_recognition_study --quick prints every table and writes a data set that taxel-describe and
# taxel-train read: describing images.npy with labels.txt reproduces the study's own feature
# files byte for byte, and taxel-train cross-validates them.
include(${CMAKE_CURRENT_LIST_DIR}/cli_common.cmake)

run_tool("${STUDY}" 0 --quick --out "${WORK_DIR}/study")
foreach(section "Edged/edgeless decision" "Table 2:" "mean .*time .* us" "Subject-grouped"
        "Table 3:" "FFNN" "kNN" "SVM-RBF" "LDA" "Fig. 5:" "clean" "drop from clean to 10 dB")
  expect("${out}" "${section}")
endforeach()
foreach(f images.npy labels.txt conventional.libsvm hybrid.libsvm accuracy_vs_snr.svg report.txt)
  if(NOT EXISTS "${WORK_DIR}/study/${f}")
    message(FATAL_ERROR "06_recognition_study did not write ${f}")
  endif()
endforeach()
file(GLOB samples "${WORK_DIR}/study/samples.*")
if(NOT samples)
  message(FATAL_ERROR "06_recognition_study wrote no sample picture")
endif()
file(READ "${WORK_DIR}/study/report.txt" report)
expect("${report}" "Table 3:")

# On one thread the same tables (timings aside) and the same files as on every core. The timings
# go with the padding of their fields: a time of 9.8 us and one of 10.5 us leave different
# blanks before them.
run_tool("${STUDY}" 0 --quick --threads 1 --out "${WORK_DIR}/study1")
file(READ "${WORK_DIR}/study1/report.txt" report1)
foreach(var report report1)
  string(REGEX REPLACE " *[0-9.]+ us|\\( *[0-9.]+ s\\)|total [0-9.]+ s|[^\n]*study1?/" ""
         ${var} "${${var}}")
endforeach()
if(NOT report STREQUAL report1)
  message(FATAL_ERROR "06_recognition_study reports differently on one thread:\n${report}\n----\n${report1}")
endif()
foreach(f images.npy labels.txt conventional.libsvm hybrid.libsvm accuracy_vs_snr.svg)
  file(SHA256 "${WORK_DIR}/study/${f}" a)
  file(SHA256 "${WORK_DIR}/study1/${f}" b)
  if(NOT a STREQUAL b)
    message(FATAL_ERROR "06_recognition_study wrote ${f} differently on one thread")
  endif()
endforeach()

foreach(kind conventional hybrid)
  set(flag "")
  if(kind STREQUAL "hybrid")
    set(flag --hybrid)
  endif()
  run_tool("${DESCRIBE}" 0 --format libsvm ${flag} --labels study/labels.txt -o ${kind}.libsvm
           study/images.npy)
  file(SHA256 "${WORK_DIR}/${kind}.libsvm" mine)
  file(SHA256 "${WORK_DIR}/study/${kind}.libsvm" theirs)
  if(NOT mine STREQUAL theirs)
    message(FATAL_ERROR "taxel-describe's ${kind} features differ from the study's")
  endif()
endforeach()
run_tool("${TRAIN}" 0 -v 5 -c 0.01 study/conventional.libsvm)
expect("${out}" "Cross Validation Accuracy = [0-9.]+%")
