// SPDX-License-Identifier: MIT
// Markers: the dark dots printed on many gels to track shear. They are not shading: a pixel of
// a dot says nothing of the gel's gradient there, so calibration leaves the dots out and
// reconstruction fills their gradients from the pixels around them.
// A pixel belongs to a dot when its luminance (the mean of the channels) is below `dark` times
// the brightest luminance within `reach` pixels (a grey-level dilation, which a dot narrower
// than the window does not survive, while the smooth shading of a press does). The dots of the
// frame and of the background are both left out, each grown by `grow` pixels.
#pragma once

#include <algorithm>
#include <cstdint>
#include <deque>
#include <stdexcept>
#include <vector>

#include "taxel/optical/types.hpp"

namespace taxel::optical {

/// How dots are found.
struct MarkerOptions {
  double dark = 0.5;  ///< a dot pixel is darker than this share of its neighbourhood's brightest
  int reach = 6;      ///< half-width of that neighbourhood [px], more than a dot's radius
  int grow = 1;       ///< pixels added around each dot
};

/// The dot pixels of one frame (see the header comment). Throws std::invalid_argument for bad
/// options.
template <class = void>
image::Mask marker_mask(const RgbFrame& frame, const MarkerOptions& o = {}) {
  validate_frame(frame, "marker_mask");
  if (!(o.dark > 0 && o.dark < 1) || o.reach < 1 || o.grow < 0) {
    throw std::invalid_argument("marker_mask: dark in (0, 1), reach >= 1 and grow >= 0");
  }
  const auto rows = static_cast<int>(frame.rows), cols = static_cast<int>(frame.cols);
  Plane lum(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      const std::uint8_t* p = frame.data.data() + (static_cast<std::size_t>(r) * cols + c) * 3;
      lum(r, c) = (double(p[0]) + p[1] + p[2]) / 3.0;
    }
  }
  // Separable running maximum: along rows, then along columns.
  Plane across(rows, cols), brightest(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      double m = 0;
      for (int k = std::max(0, c - o.reach); k <= std::min(cols - 1, c + o.reach); ++k) {
        m = std::max(m, lum(r, k));
      }
      across(r, c) = m;
    }
  }
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      double m = 0;
      for (int k = std::max(0, r - o.reach); k <= std::min(rows - 1, r + o.reach); ++k) {
        m = std::max(m, across(k, c));
      }
      brightest(r, c) = m;
    }
  }
  image::Mask mask(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) mask(r, c) = lum(r, c) < o.dark * brightest(r, c) ? 1 : 0;
  }
  for (int g = 0; g < o.grow; ++g) {
    const image::Mask m = mask;
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (!m(r, c) && ((r > 0 && m(r - 1, c)) || (r + 1 < rows && m(r + 1, c)) ||
                         (c > 0 && m(r, c - 1)) || (c + 1 < cols && m(r, c + 1)))) {
          mask(r, c) = 1;
        }
      }
    }
  }
  return mask;
}

/// Fills the pixels of `plane` where `holes` is non-zero from the others: in order of their
/// 4-connected distance to a pixel outside the holes, each takes the mean of its neighbours
/// filled or outside before it. A plane that is all holes is left as it is. Throws
/// std::invalid_argument for sizes that differ.
template <class = void>
void fill_holes(Plane& plane, const image::Mask& holes) {
  if (plane.rows() != holes.rows() || plane.cols() != holes.cols()) {
    throw std::invalid_argument("fill_holes: the plane and the mask differ in size");
  }
  const auto rows = static_cast<int>(plane.rows()), cols = static_cast<int>(plane.cols());
  std::vector<int> dist(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols), -1);
  std::deque<int> queue;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (!holes(r, c)) {
        dist[static_cast<std::size_t>(r * cols + c)] = 0;
        queue.push_back(r * cols + c);
      }
    }
  }
  std::vector<int> order;
  while (!queue.empty()) {
    const int i = queue.front();
    queue.pop_front();
    const int r = i / cols, c = i % cols;
    const int next[4][2] = {{r - 1, c}, {r + 1, c}, {r, c - 1}, {r, c + 1}};
    for (const auto& [rr, cc] : next) {
      if (rr < 0 || cc < 0 || rr >= rows || cc >= cols) continue;
      int& d = dist[static_cast<std::size_t>(rr * cols + cc)];
      if (d >= 0) continue;
      d = dist[static_cast<std::size_t>(i)] + 1;
      queue.push_back(rr * cols + cc);
      order.push_back(rr * cols + cc);
    }
  }
  for (const int i : order) {
    const int r = i / cols, c = i % cols, d = dist[static_cast<std::size_t>(i)];
    double sum = 0, n = 0;
    const int next[4][2] = {{r - 1, c}, {r + 1, c}, {r, c - 1}, {r, c + 1}};
    for (const auto& [rr, cc] : next) {
      if (rr < 0 || cc < 0 || rr >= rows || cc >= cols) continue;
      const int dn = dist[static_cast<std::size_t>(rr * cols + cc)];
      if (dn < 0 || dn >= d) continue;
      sum += plane(rr, cc);
      n += 1;
    }
    if (n > 0) plane(r, c) = sum / n;
  }
}

}  // namespace taxel::optical
