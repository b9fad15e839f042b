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
#include <cstddef>
#include <cstdint>
#include <deque>
#include <stdexcept>
#include <vector>

#include "taxel/optical/types.hpp"

namespace taxel::optical {

namespace detail {
// The maximum of x over [i - reach, i + reach] (clipped) for every i, in O(1) per element (van
// Herk, "A fast algorithm for local minimum and maximum filters on rectangular and octagonal
// kernels", Pattern Recognition Letters 13(7), 1992): prefix maxima g and suffix maxima h
// within blocks of 2 reach + 1; a window spans at most two blocks.
inline void running_max(const std::vector<double>& x, int reach, std::vector<double>& g,
                        std::vector<double>& h, std::vector<double>& out) {
  const auto n = static_cast<std::ptrdiff_t>(x.size());
  const std::ptrdiff_t w = 2 * static_cast<std::ptrdiff_t>(reach) + 1;
  g.resize(x.size());
  h.resize(x.size());
  out.resize(x.size());
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    g[k] = i % w == 0 ? x[k] : std::max(g[k - 1], x[k]);
  }
  for (std::ptrdiff_t i = n - 1; i >= 0; --i) {
    const auto k = static_cast<std::size_t>(i);
    h[k] = i == n - 1 || (i + 1) % w == 0 ? x[k] : std::max(h[k + 1], x[k]);
  }
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const std::ptrdiff_t a = std::max<std::ptrdiff_t>(i - reach, 0);
    const std::ptrdiff_t b = std::min<std::ptrdiff_t>(i + reach, n - 1);
    const auto ka = static_cast<std::size_t>(a), kb = static_cast<std::size_t>(b);
    if (a / w != b / w) {
      out[static_cast<std::size_t>(i)] = std::max(h[ka], g[kb]);
    } else {
      out[static_cast<std::size_t>(i)] = a % w == 0 ? g[kb] : h[ka];
    }
  }
}
}  // namespace detail

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
  std::vector<double> line, g, h, out;
  for (int r = 0; r < rows; ++r) {
    line.assign(lum.row(r).data(), lum.row(r).data() + cols);
    detail::running_max(line, o.reach, g, h, out);
    for (int c = 0; c < cols; ++c) across(r, c) = out[static_cast<std::size_t>(c)];
  }
  for (int c = 0; c < cols; ++c) {
    line.resize(static_cast<std::size_t>(rows));
    for (int r = 0; r < rows; ++r) line[static_cast<std::size_t>(r)] = across(r, c);
    detail::running_max(line, o.reach, g, h, out);
    for (int r = 0; r < rows; ++r) brightest(r, c) = out[static_cast<std::size_t>(r)];
  }
  image::Mask mask(rows, cols);
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) mask(r, c) = lum(r, c) < o.dark * brightest(r, c) ? 1 : 0;
  }
  for (int step = 0; step < o.grow; ++step) {
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
  // Seeds: the pixels outside the holes next to one (the others are never a neighbour).
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (holes(r, c)) continue;
      dist[static_cast<std::size_t>(r * cols + c)] = 0;
      if ((r > 0 && holes(r - 1, c)) || (r + 1 < rows && holes(r + 1, c)) ||
          (c > 0 && holes(r, c - 1)) || (c + 1 < cols && holes(r, c + 1))) {
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
