// SPDX-License-Identifier: MIT
// A pad's compression against a shape, and the footprint quadrature of a tactel that reads its
// mean compression (sim/sensor.hpp's read_pad and sim/contact_stream.hpp).
#pragma once

#include <algorithm>

#include "taxel/core/types.hpp"
#include "taxel/sensor/pad.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// How far a tactel at `at`, inside the shape, is pushed back along `back` (unit) until it leaves
/// the shape: the pad's compression there [m]. Sphere tracing: each step moves by the distance to
/// the surface, which never overshoots it.
template <Shape Sh>
double compression(const Sh& shape, const Vec3d& at, const Vec3d& back) {
  double t = 0.0;
  for (int it = 0; it < 200; ++it) {
    const double d = -shape.signed_distance(at + t * back);
    if (d <= 1e-12) break;
    t += std::max(d, 1e-10);
  }
  return t;
}

// The footprint quadrature lives with the pad (sensor/pad.hpp); the simulators use it by these
// names.
using sensor::kGaussNode;
using sensor::kGaussWeight;

}  // namespace taxel::sim
