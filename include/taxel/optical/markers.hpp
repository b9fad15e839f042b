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
inline void running_max(const std::vector<double>& x, int reach, std::vector<double>& g,
                        std::vector<double>& h, std::vector<double>& out) {
  const auto n = static_cast<int>(x.size());
  g.resize(x.size());
  h.resize(x.size());
  out.resize(x.size());
  const auto at = [](std::vector<double>& v) {
    return [&v](int i) -> double& { return v[static_cast<std::size_t>(i)]; };
  };
  van_herk(
      n, reach, [&](int i) { return x[static_cast<std::size_t>(i)]; }, at(g), at(h), at(out),
      [](double& to, double a, double b) { to = std::max(a, b); },
      [](double& to, double a) { to = a; });
}

// The running maximum over (2 reach + 1)^2 squares (clipped at the borders) of a plane: along
// each row, then along the columns a whole row at a time.
inline Plane running_max_2d(const Plane& x, int reach) {
  const auto rows = static_cast<int>(x.rows()), cols = static_cast<int>(x.cols());
  Plane across(rows, cols), out(rows, cols);
  std::vector<double> line, g, h, res;
  for (int r = 0; r < rows; ++r) {
    line.assign(x.row(r).data(), x.row(r).data() + cols);
    running_max(line, reach, g, h, res);
    std::copy(res.begin(), res.end(), across.row(r).data());
  }
  Plane gp(rows, cols), hp(rows, cols);
  using Row = decltype(out.row(0));
  van_herk(
      rows, reach, [&](int i) { return across.row(i); }, [&](int i) { return gp.row(i); },
      [&](int i) { return hp.row(i); }, [&](int i) { return out.row(i); },
      [](Row to, const auto& a, const auto& b) { to = a.max(b); },
      [](Row to, const auto& a) { to = a; });
  return out;
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
  const Plane brightest = detail::running_max_2d(lum, o.reach);
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
