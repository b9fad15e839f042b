// SPDX-License-Identifier: MIT
// taxel version; kept equal to project(VERSION) in CMakeLists.txt (checked by a test).
#pragma once

#define TAXEL_VERSION_MAJOR 0
#define TAXEL_VERSION_MINOR 1
#define TAXEL_VERSION_PATCH 0
/// The version as a string, "major.minor.patch".
#define TAXEL_VERSION_STRING "0.1.0"
