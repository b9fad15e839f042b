// SPDX-License-Identifier: MIT
// A pad's compression against a shape, and the footprint quadrature of a tactel that reads its
// mean compression (sim/sensor.hpp's read_pad and sim/contact_stream.hpp).
#pragma once

#include <algorithm>

#include "taxel/core/types.hpp"
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

/// Gauss-Legendre nodes on [-1/2, 1/2] for 1 to 4 points (row n - 1), and their weights
/// (summing to 1): a tactel's footprint is integrated on them, n per side.
inline constexpr double kGaussNode[4][4] = {
    {0.0},
    {-0.28867513459481287, 0.28867513459481287},
    {-0.3872983346207417, 0.0, 0.3872983346207417},
    {-0.43056815579702629, -0.16999052179242813, 0.16999052179242813, 0.43056815579702629}};
/// See kGaussNode.
inline constexpr double kGaussWeight[4][4] = {
    {1.0},
    {0.5, 0.5},
    {0.2777777777777778, 0.4444444444444444, 0.2777777777777778},
    {0.17392742256872692, 0.32607257743127307, 0.32607257743127307, 0.17392742256872692}};

}  // namespace taxel::sim
