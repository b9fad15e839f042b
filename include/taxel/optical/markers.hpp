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
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <stdexcept>
#include <vector>

#include "taxel/optical/types.hpp"

namespace taxel::optical {

namespace detail {
// The maximum over [i - reach, i + reach] (clipped) for every i of a sequence, in O(1) per
// element (van Herk, "A fast algorithm for local minimum and maximum filters on rectangular and
// octagonal kernels", Pattern Recognition Letters 13(7), 1992): prefix maxima g and suffix
// maxima h within blocks of w = 2 reach + 1; a full window [a, a + w - 1] spans at most two
// blocks and its maximum is max(h[a], g[a + w - 1]). Windows clipped at the ends are prefix or
// suffix maxima of the whole sequence. The elements are doubles (one sequence) or the rows of
// a plane (its columns at once: the same steps, element-wise); x, g, h and out give element i.
template <class Get, class G, class H, class Out, class Max, class Copy>
void van_herk(int n, int reach, Get x, G g, H h, Out out, Max max, Copy copy) {
  const int w = 2 * reach + 1;
  for (int b = 0; b < n; b += w) {
    const int e = std::min(b + w, n);
    copy(g(b), x(b));
    for (int i = b + 1; i < e; ++i) max(g(i), g(i - 1), x(i));
    copy(h(e - 1), x(e - 1));
    for (int i = e - 2; i >= b; --i) max(h(i), h(i + 1), x(i));
  }
  // Clipped at the start: [0, i + reach] for i < reach + 1; at the end: [i - reach, n - 1].
  const int head = std::min(n, reach + 1), tail = std::max(head, n - reach);
  if (head > 0) {
    copy(out(0), x(0));
    for (int k = 1; k <= std::min(reach, n - 1); ++k) max(out(0), out(0), x(k));
    for (int i = 1; i < head; ++i) {
      copy(out(i), out(i - 1));
      if (i + reach < n) max(out(i), out(i), x(i + reach));
    }
  }
  for (int i = head; i < tail; ++i) max(out(i), h(i - reach), g(i + reach));
  if (tail < n) {
    copy(out(n - 1), x(n - 1));
    for (int k = n - 2; k >= std::max(0, n - 1 - reach); --k) max(out(n - 1), out(n - 1), x(k));
    for (int i = n - 2; i >= tail; --i) {
      copy(out(i), out(i + 1));
      if (i - reach >= 0) max(out(i), out(i), x(i - reach));
    }
  }
}

// The 1-D running maximum of x (see van_herk) into out; g and h are workspace.
// The mask grown by one pixel to its 4-neighbours (rows and columns shifted, whole rows at a
// time, which Eigen vectorises).
inline image::Mask dilate4(const image::Mask& m) {
  const Eigen::Index rows = m.rows(), cols = m.cols();
  image::Mask out = m;
  if (rows > 1) {
    out.topRows(rows - 1) = out.topRows(rows - 1).max(m.bottomRows(rows - 1));
    out.bottomRows(rows - 1) = out.bottomRows(rows - 1).max(m.topRows(rows - 1));
  }
  if (cols > 1) {
    out.leftCols(cols - 1) = out.leftCols(cols - 1).max(m.rightCols(cols - 1));
    out.rightCols(cols - 1) = out.rightCols(cols - 1).max(m.leftCols(cols - 1));
  }
  return out;
}

// The running maximum down each column of x (rows i - reach .. i + reach, clipped): van Herk's
// passes on whole rows, which Eigen vectorises.
template <class A>
A running_max_columns(const A& x, int reach) {
  const auto rows = static_cast<int>(x.rows());
  A gp(x.rows(), x.cols()), hp(x.rows(), x.cols()), out(x.rows(), x.cols());
  using Row = decltype(out.row(0));
  van_herk(
      rows, reach, [&](int i) { return x.row(i); }, [&](int i) { return gp.row(i); },
      [&](int i) { return hp.row(i); }, [&](int i) { return out.row(i); },
      [](Row to, const auto& p, const auto& q) { to = p.max(q); },
      [](Row to, const auto& p) { to = p; });
  return out;
}

// The maximum over the (2 reach + 1)^2 square around each pixel, clipped at the borders, of a
// row-major Eigen array: down the columns of the transpose (along the rows), then down the
// columns, so that both passes run on whole rows.
template <class A>
A running_max_2d(const A& x, int reach) {
  const A t = x.transpose();
  const A across = running_max_columns(t, reach).transpose();
  return running_max_columns(across, reach);
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
  // Luminance as the sum of the channels (0..765): 16-bit integers, whose running maximum
  // vectorises 8 wide, and the same comparison as of the channels' mean.
  image::Image<std::int16_t> sum(rows, cols);
  const std::uint8_t* p = frame.data.data();
  for (Eigen::Index i = 0; i < sum.size(); ++i, p += 3) {
    sum.data()[i] = static_cast<std::int16_t>(p[0] + p[1] + p[2]);
  }
  const image::Image<std::int16_t> brightest = detail::running_max_2d(sum, o.reach);
  // A dot pixel: sum < dark * brightest, that is sum < first[brightest], the least whole sum
  // that is not darker (a table over the 766 possible maxima).
  std::int16_t first[766];
  for (int m = 0; m < 766; ++m) first[m] = static_cast<std::int16_t>(std::ceil(o.dark * m));
  image::Mask mask(rows, cols);
  for (Eigen::Index i = 0; i < sum.size(); ++i) {
    mask.data()[i] = sum.data()[i] < first[brightest.data()[i]] ? 1 : 0;
  }
  for (int step = 0; step < o.grow; ++step) mask = detail::dilate4(mask);
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
