// SPDX-License-Identifier: MIT
// Umbrella header of taxel::index.
#pragma once

#include "taxel/index/brute_force.hpp"
#include "taxel/index/concepts.hpp"
#include "taxel/index/dynamic_kdtree.hpp"
#include "taxel/index/kdtree.hpp"
#include "taxel/index/uniform_grid.hpp"
#include "taxel/index/voxel_hash.hpp"
