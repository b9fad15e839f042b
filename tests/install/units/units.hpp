// SPDX-License-Identifier: MIT
// Three translation units of one consumer program, each including the whole of the installed
// taxel and calling different parts of it, main.cpp again the calls the other two make. Linking
// them together checks that every header is safe to include in many files of one program (a
// function defined in a header without `inline` is defined once per translation unit that
// includes it, whether called or not, and the link fails) and that the same instantiations
// from several units merge. Each function returns the number of its checks that failed.
#pragma once

int unit_fusion();
int unit_index();
int unit_io();
int unit_sim();
int unit_sensor();
int unit_registration();
int unit_image();
int unit_learn();
