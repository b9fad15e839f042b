// SPDX-License-Identifier: MIT
// Umbrella header of taxel::shape: the touched object's surface with its uncertainty (a
// Gaussian-process implicit surface over local experts), its mesh, and where to touch next.
#pragma once

#include "taxel/shape/explorer.hpp"
#include "taxel/shape/gaussian_process.hpp"
#include "taxel/shape/grid.hpp"
#include "taxel/shape/implicit_surface.hpp"
#include "taxel/shape/kernels.hpp"
#include "taxel/shape/marching.hpp"
#include "taxel/shape/next_touch.hpp"
#include "taxel/shape/recognition.hpp"
#include "taxel/shape/surface_mesh.hpp"
