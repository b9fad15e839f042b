// SPDX-License-Identifier: MIT
// Umbrella header of taxel::io (without io/png.hpp, which needs libpng at link time).
// Thread-safety: the readers, parsers and encoders are free functions without shared state and
// may run on several threads at once; write_file (and the writers built on it) too, on distinct
// paths. Limits: read_file refuses files over 1 GiB, the image readers over 2^24 values, the
// libsvm reader dense sets over LibsvmReadOptions::max_values (2^24), before allocating.
#pragma once

#include "taxel/io/contacts_csv.hpp"
#include "taxel/io/file.hpp"
#include "taxel/io/image.hpp"
#include "taxel/io/libsvm_format.hpp"
#include "taxel/io/npy.hpp"
#include "taxel/io/pad_poses_csv.hpp"
#include "taxel/io/picture.hpp"
#include "taxel/io/ply.hpp"
#include "taxel/io/svg_plot.hpp"
