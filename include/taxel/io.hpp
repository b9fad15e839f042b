// SPDX-License-Identifier: MIT
// Umbrella header of taxel::io (without io/png.hpp, which needs libpng at link time).
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
