// SPDX-License-Identifier: MIT
// Ten translation units of one consumer program, each including the whole of the
// installed taxel and calling a different part of it. Linking them together checks
// that every header is safe to include in many files of one program (no duplicate symbols);
// each returns the number of its checks that failed.
#pragma once

int unit_fusion();
int unit_index();
int unit_registration();
int unit_image();
int unit_learn();
int unit_io();
int unit_sim();
int unit_sensor();
int unit_all();
