// SPDX-License-Identifier: MIT
// Region descriptors with MATLAB `regionprops` conventions (as MathWorks documents them): pixel
// centres at integer coordinates, x = column, y = row, 1-based by default; second moments with
// y pointing up and +1/12 for each pixel's extent; ConvexArea as a pixel count of the hull of
// the pixels' edge midpoints, rasterised with poly2mask's 5x5 sub-pixel rule.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/image/components.hpp"
#include "taxel/image/types.hpp"

namespace taxel::image {

/// Which descriptors to compute, and the coordinate origin.
struct RegionPropsOptions {
  /// false (default): MATLAB's 1-based pixel coordinates; true: 0-based (centroid, bounding
  /// box and hull all shift by -1).
  bool zero_based = false;
  bool convex = true;     ///< convex hull, ConvexArea, Solidity
  bool perimeter = true;  ///< Perimeter (traces the outer boundary of every 8-component)
};

/// Descriptors of one region (or of the union of several, treated as one region, as MATLAB
/// does for a logical image). An empty region has `area == 0` and every other field 0.
struct RegionProps {
  double area = 0;                           ///< pixel count
  Eigen::Vector2d centroid{0, 0};            ///< (mean x, mean y) = (mean column, mean row)
  Eigen::Vector4d bounding_box{0, 0, 0, 0};  ///< [ulx, uly, width, height], corner on pixel edges
  double major_axis = 0;                     ///< MajorAxisLength of the same-second-moment ellipse
  double minor_axis = 0;                     ///< MinorAxisLength
  double eccentricity = 0;                   ///< in [0, 1): 0 for a circle
  double orientation = 0;                    ///< degrees in [-90, 90], counter-clockwise, y up
  double convex_area = 0;                    ///< pixels inside the convex hull (poly2mask rule)
  std::vector<Eigen::Vector2d> convex_hull;  ///< hull vertices (x, y), counter-clockwise on
                                             ///< screen, first vertex not repeated
  double solidity = 0;                       ///< area / convex_area
  double extent = 0;                         ///< area / bounding-box area
  double equiv_diameter = 0;                 ///< sqrt(4 area / pi)
  int euler_number = 0;   ///< objects - holes, objects 8-connected (MATLAB default)
  int euler_number4 = 0;  ///< objects - holes, objects 4-connected
  double perimeter = 0;   ///< chain-code length of the outer boundaries, see below
};

/// Region-descriptor workspace; reusing it for images of one size allocates nothing once the
/// hull buffers have grown to their largest size.
///
/// Perimeter: for every 8-connected component the outer boundary is traced (Moore neighbours,
/// starting at the first pixel in column order, as bwboundaries does) and its steps are weighted
/// with the Vossepoel-Smeulders coefficients: 0.980 per axis step, 1.406 per diagonal step,
/// -0.091 per change of step type; a single pixel has perimeter 0. Holes are not counted. For a
/// union of several components the lengths add.
/// Not thread-safe (a reused workspace); one per thread.
class RegionAnalyzer {
 public:
  /// A workspace for masks up to rows x cols (it grows for larger ones).
  explicit RegionAnalyzer(RegionPropsOptions opt = {}, Eigen::Index rows = 32,
                          Eigen::Index cols = 32)
      : opt_(opt), components_((detail::checked_pixels("RegionAnalyzer", rows, cols), rows), cols) {
    points_.reserve(4 * static_cast<std::size_t>(rows) + 8);
    hull_.reserve(4 * static_cast<std::size_t>(rows) + 8);
    row_first_.reserve(static_cast<std::size_t>(rows));
    row_last_.reserve(static_cast<std::size_t>(rows));
    quad_.reserve(2 * static_cast<std::size_t>(cols + 2));
    packed_.reserve(static_cast<std::size_t>(rows));
    props_.convex_hull.reserve(6 * static_cast<std::size_t>(rows) + 8);
    parity_.resize(rows, cols);
    convex_image_.resize(rows, cols);
    boundary_.reserve(static_cast<std::size_t>(4 * rows * cols) + 8);
  }

  /// The options.
  [[nodiscard]] const RegionPropsOptions& options() const noexcept { return opt_; }

  /// Descriptors of the non-zero pixels of `mask`, taken as one region.
  template <class D = void>
  const Deferred<RegionProps, D>& compute(const Deferred<MaskView, D>& mask) {
    RegionProps& p = props_;
    p.convex_hull.clear();
    p.area = 0;
    p.centroid.setZero();
    p.bounding_box.setZero();
    p.major_axis = p.minor_axis = p.eccentricity = p.orientation = 0;
    p.convex_area = p.solidity = p.extent = p.equiv_diameter = p.perimeter = 0;
    p.euler_number = p.euler_number4 = 0;
    convex_image_.resize(0, 0);

    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    // One pass: count, first and second moments as exact integers, bounding box, and the
    // first and last pixel of every row (for the hull).
    std::int64_t n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    Eigen::Index rmin = rows, rmax = -1, cmin = cols, cmax = -1;
    row_first_.assign(static_cast<std::size_t>(rows), -1);
    row_last_.assign(static_cast<std::size_t>(rows), -1);
    const Eigen::Index stride = mask.outerStride();
    // Masks up to kPackedCols wide are packed into one 64-bit word per row (with room for a
    // zero border on both sides): moments come from the runs of each row, the Euler number
    // from population counts of row pairs.
    const bool packed = cols <= kPackedCols;
    if (packed) packed_.resize(static_cast<std::size_t>(rows));
    for (Eigen::Index r = 0; r < rows; ++r) {
      const std::uint8_t* m = mask.data() + r * stride;
      std::int64_t rn = 0, rs = 0, rss = 0;
      Eigen::Index first = 0, last = 0;
      if (packed) {
        std::uint64_t bits = detail::pack_row(m, cols);
        packed_[static_cast<std::size_t>(r)] = bits;
        if (bits == 0) continue;
        first = std::countr_zero(bits);
        last = 63 - std::countl_zero(bits);
        // Sum of c and c^2 over a run a..b: closed forms.
        auto squares = [](std::int64_t k) { return k * (k + 1) * (2 * k + 1) / 6; };
        while (bits != 0) {
          const int a = std::countr_zero(bits);
          const int len = std::countr_one(bits >> a);
          const int b = a + len - 1;
          rn += len;
          rs += static_cast<std::int64_t>(a + b) * len / 2;
          rss += squares(b) - squares(a - 1);
          bits = b >= 63 ? 0 : bits & (~std::uint64_t{0} << (b + 1));
        }
      } else {
        // Branch-free: a region's edges within a row are unpredictable.
        for (Eigen::Index c = 0; c < cols; ++c) {
          const std::int64_t b = m[c] != 0 ? 1 : 0;
          rn += b;
          rs += b * c;
          rss += b * c * c;
        }
        if (rn == 0) continue;
        while (m[first] == 0) ++first;
        last = cols - 1;
        while (m[last] == 0) --last;
      }
      row_first_[static_cast<std::size_t>(r)] = first;
      row_last_[static_cast<std::size_t>(r)] = last;
      n += rn;
      sx += rs;
      sxx += rss;
      sy += rn * r;
      syy += rn * r * r;
      sxy += rs * r;
      rmin = std::min(rmin, r);
      rmax = r;
      cmin = std::min(cmin, first);
      cmax = std::max(cmax, last);
    }
    if (n == 0) return p;
    const double base = opt_.zero_based ? 0.0 : 1.0;
    const auto nd = static_cast<double>(n);
    const double xbar = static_cast<double>(sx) / nd;  // 0-based
    const double ybar = static_cast<double>(sy) / nd;
    p.area = nd;
    p.centroid = {xbar + base, ybar + base};
    const auto w = static_cast<double>(cmax - cmin + 1);
    const auto h = static_cast<double>(rmax - rmin + 1);
    p.bounding_box = {static_cast<double>(cmin) + base - 0.5,
                      static_cast<double>(rmin) + base - 0.5, w, h};
    p.extent = nd / (w * h);
    p.equiv_diameter = std::sqrt(4.0 * nd / std::numbers::pi);

    // Central second moments, y up, with the 1/12 of each pixel's own extent. For sides up to
    // 1024 px, n^2 mu = n sxx - sx^2 is exact in 64-bit integers (below side^6 <= 2^60) and
    // rounded once; larger images take a second, centred pass in floating point.
    double uxx = 0, uyy = 0, uxy = 0;
    if (std::max(rows, cols) <= 1024) {
      const double n2 = nd * nd;
      uxx = static_cast<double>(n * sxx - sx * sx) / n2;
      uyy = static_cast<double>(n * syy - sy * sy) / n2;
      uxy = -static_cast<double>(n * sxy - sx * sy) / n2;
    } else {
      for (Eigen::Index r = rmin; r <= rmax; ++r) {
        for (Eigen::Index c = cmin; c <= cmax; ++c) {
          if (mask(r, c) == 0) continue;
          const double x = static_cast<double>(c) - xbar;
          const double y = -(static_cast<double>(r) - ybar);
          uxx += x * x;
          uyy += y * y;
          uxy += x * y;
        }
      }
      uxx /= nd;
      uyy /= nd;
      uxy /= nd;
    }
    uxx += 1.0 / 12.0;
    uyy += 1.0 / 12.0;
    const double common = std::sqrt((uxx - uyy) * (uxx - uyy) + 4 * uxy * uxy);
    p.major_axis = 2 * std::numbers::sqrt2 * std::sqrt(uxx + uyy + common);
    p.minor_axis = 2 * std::numbers::sqrt2 * std::sqrt(std::max(0.0, uxx + uyy - common));
    const double ratio = p.minor_axis / p.major_axis;
    p.eccentricity = std::sqrt(std::max(0.0, 1.0 - ratio * ratio));
    double num = 0, den = 0;
    if (uyy > uxx) {
      num = uyy - uxx + std::sqrt((uyy - uxx) * (uyy - uxx) + 4 * uxy * uxy);
      den = 2 * uxy;
    } else {
      num = 2 * uxy;
      den = uxx - uyy + std::sqrt((uxx - uyy) * (uxx - uyy) + 4 * uxy * uxy);
    }
    if (num == 0 && den == 0) {
      p.orientation = 0;
    } else if (den == 0) {
      p.orientation = num > 0 ? 90.0 : -90.0;
    } else {
      p.orientation = std::atan(num / den) * 180.0 / std::numbers::pi;
    }

    euler(mask, rmin, rmax, cmin, cmax);
    if (opt_.convex) convex(rmin, rmax, cmin, cmax, base);
    if (opt_.perimeter) perimeter(mask);
    return p;
  }

  /// The last descriptors.
  [[nodiscard]] const RegionProps& result() const noexcept { return props_; }

  /// MATLAB's ConvexImage of the last region: the bounding-box-sized mask of pixels inside the
  /// hull (empty when the region is empty or `convex` is off).
  [[nodiscard]] const Mask& convex_image() const noexcept { return convex_image_; }

 private:
  // Euler numbers from Gray's bit-quad counts over the zero-padded bounding box: each row pair
  // is packed into one 0/1 byte row with a zero border, and the 2x2 windows are tallied
  // without branches.
  template <class D = void>
  void euler(const Deferred<MaskView, D>& mask, Eigen::Index rmin, Eigen::Index rmax,
             Eigen::Index cmin, Eigen::Index cmax) {
    if (mask.cols() <= kPackedCols) {
      // Bit j of a row word shifted left by one is the pixel of window column j - 1, so bit 0
      // and bit cols + 1 are the zero border; window j spans bits j and j + 1.
      const std::uint64_t valid = (std::uint64_t{1} << (mask.cols() + 1)) - 1;
      std::uint64_t prev = 0;
      int q1 = 0, q3 = 0, qd = 0;
      for (Eigen::Index r = rmin; r <= rmax + 1; ++r) {
        const std::uint64_t cur = r <= rmax ? packed_[static_cast<std::size_t>(r)] << 1 : 0;
        const std::uint64_t a = prev, b = prev >> 1, d = cur, e = cur >> 1;
        const std::uint64_t odd = (a ^ b ^ d ^ e) & valid;  // one or three set
        const std::uint64_t pairs = (a & b) | (d & e);      // with an odd sum: three set
        q1 += std::popcount(odd & ~pairs);
        q3 += std::popcount(odd & pairs);
        qd += std::popcount(((a & e & ~b & ~d) | (b & d & ~a & ~e)) & valid);
        prev = cur;
      }
      props_.euler_number = (q1 - q3 - 2 * qd) / 4;
      props_.euler_number4 = (q1 - q3 + 2 * qd) / 4;
      return;
    }
    const Eigen::Index w = cmax - cmin + 1;
    const auto padded = static_cast<std::size_t>(w + 2);
    quad_.assign(2 * padded, 0);
    std::uint8_t* above = quad_.data();
    std::uint8_t* below = quad_.data() + padded;
    int q1 = 0, q3 = 0, qd = 0;
    const Eigen::Index stride = mask.outerStride();
    for (Eigen::Index r = rmin; r <= rmax + 1; ++r) {
      if (r <= rmax) {
        const std::uint8_t* m = mask.data() + r * stride + cmin;
        for (Eigen::Index c = 0; c < w; ++c) below[c + 1] = m[c] != 0 ? 1 : 0;
      } else {
        std::fill(below, below + padded, std::uint8_t{0});
      }
      for (std::size_t c = 0; c + 1 < padded; ++c) {
        const int a = above[c], b = above[c + 1], d = below[c], e = below[c + 1];
        const int sum = a + b + d + e;
        q1 += sum == 1 ? 1 : 0;
        q3 += sum == 3 ? 1 : 0;
        qd += ((sum == 2) & (a == e)) ? 1 : 0;
      }
      std::swap(above, below);
    }
    props_.euler_number = (q1 - q3 - 2 * qd) / 4;
    props_.euler_number4 = (q1 - q3 + 2 * qd) / 4;
  }

  struct P2 {
    std::int64_t x, y;  // doubled coordinates
  };
  static std::int64_t cross(const P2& o, const P2& a, const P2& b) noexcept {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  }

  // MATLAB round: half away from zero on the value n/2 (n integer).
  static std::int64_t round_half(std::int64_t n) noexcept {
    if (n % 2 == 0) return n / 2;
    return n > 0 ? (n + 1) / 2 : (n - 1) / 2;
  }
  // MATLAB round of a double: half away from zero.
  static std::int64_t round_away(double v) noexcept {
    return v >= 0 ? static_cast<std::int64_t>(v + 0.5) : -static_cast<std::int64_t>(-v + 0.5);
  }
  static std::int64_t floor_div(std::int64_t a, std::int64_t b) noexcept {
    std::int64_t q = a / b;
    if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
    return q;
  }

  // Toggles parity_ where the segment (x1, y1) -> (x2, y2) of the 5x sub-pixel polygon
  // crosses a pixel-centre column. The segment's integer points are those poly2mask's line
  // stepping gives (along the longer axis, the other coordinate rounded half away from zero);
  // each pair of consecutive points that differ in x is a horizontal edge at (min x, min y).
  // Only edges on pixel-centre columns (x = 5 col - 2) toggle the pixel below them.
  template <class = void>
  void toggle_edges(std::int64_t x1, std::int64_t y1, std::int64_t x2, std::int64_t y2,
                    Eigen::Index rows, Eigen::Index cols) {
    const std::int64_t dx = std::abs(x2 - x1);
    const std::int64_t dy = std::abs(y2 - y1);
    if (dx == 0) return;  // no step in x: no horizontal edge
    auto toggle = [&](std::int64_t xe, std::int64_t ye) {
      if ((xe + 2) % 5 != 0) return;  // not on a pixel's centre column
      const std::int64_t col = (xe + 2) / 5;
      std::int64_t row = -floor_div(-(ye + 2), 5);  // ceil((ye + 2) / 5)
      if (col < 1 || col > cols || row > rows) return;
      row = std::max<std::int64_t>(1, row);
      parity_(row - 1, col - 1) ^= 1;
    };
    if (dx >= dy) {
      if (x1 > x2) {
        std::swap(x1, x2);
        std::swap(y1, y2);
      }
      const double m = static_cast<double>(y2 - y1) / static_cast<double>(x2 - x1);
      auto y_at = [&](std::int64_t x) {
        return round_away(static_cast<double>(y1) + m * static_cast<double>(x - x1));
      };
      // Every step moves one in x; only x = 3 (mod 5) can toggle.
      std::int64_t x = x1 + ((3 - x1) % 5 + 5) % 5;
      for (; x < x2; x += 5) toggle(x, std::min(y_at(x), y_at(x + 1)));
    } else {
      if (y1 > y2) {
        std::swap(x1, x2);
        std::swap(y1, y2);
      }
      const double m = static_cast<double>(x2 - x1) / static_cast<double>(y2 - y1);
      std::int64_t xp = x1;
      for (std::int64_t y = y1 + 1; y <= y2; ++y) {
        const std::int64_t x =
            round_away(static_cast<double>(x1) + m * static_cast<double>(y - y1));
        if (x != xp) toggle(std::min(x, xp), y - 1);
        xp = x;
      }
    }
  }

  template <class = void>
  void convex(Eigen::Index rmin, Eigen::Index rmax, Eigen::Index cmin, Eigen::Index cmax,
              double base) {
    // Candidate points: edge midpoints of the first and last pixel of every row, in doubled
    // bounding-box coordinates where pixel (1, 1) is the box's upper-left pixel. Row r's
    // midpoints lie on the levels y - 1, y, y + 1 (y = 2 (r - rmin + 1)), and only the least
    // and the greatest x of a level can be hull vertices; the levels come out in ascending
    // order, so the points are sorted by (y, x) without a sort.
    points_.clear();
    std::int64_t pend_lo = 0, pend_hi = -1;  // the level y + 1 of the previous row
    std::int64_t pend_y = -1;
    auto level = [&](std::int64_t y, std::int64_t lo, std::int64_t hi) {
      points_.push_back({lo, y});
      if (hi != lo) points_.push_back({hi, y});
    };
    for (Eigen::Index r = rmin; r <= rmax; ++r) {
      const Eigen::Index first = row_first_[static_cast<std::size_t>(r)];
      if (first < 0) continue;
      const Eigen::Index last = row_last_[static_cast<std::size_t>(r)];
      const std::int64_t y = 2 * (r - rmin + 1);
      const std::int64_t xf = 2 * (first - cmin + 1);
      const std::int64_t xl = 2 * (last - cmin + 1);
      if (pend_y == y - 1) {
        level(y - 1, std::min(pend_lo, xf), std::max(pend_hi, xl));
      } else {
        if (pend_y >= 0) level(pend_y, pend_lo, pend_hi);
        level(y - 1, xf, xl);
      }
      level(y, xf - 1, xl + 1);
      pend_y = y + 1;
      pend_lo = xf;
      pend_hi = xl;
    }
    if (pend_y >= 0) level(pend_y, pend_lo, pend_hi);

    // Andrew's monotone chain over the (y, x) order, collinear points dropped. In swapped
    // coordinates that order is the usual one and the chains come out with the opposite turn,
    // so they are reversed, then rotated to start at the least (x, y): the same vertices in
    // the same order as the chain over a sort by (x, y).
    hull_.clear();
    if (points_.size() < 3) {
      hull_ = points_;
      std::sort(hull_.begin(), hull_.end(),
                [](const P2& a, const P2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    } else {
      for (const P2& pt : points_) {
        while (hull_.size() >= 2 && cross(hull_[hull_.size() - 2], hull_.back(), pt) >= 0) {
          hull_.pop_back();
        }
        hull_.push_back(pt);
      }
      const std::size_t lower = hull_.size() + 1;
      for (std::size_t i = points_.size() - 1; i-- > 0;) {
        const P2& pt = points_[i];
        while (hull_.size() >= lower && cross(hull_[hull_.size() - 2], hull_.back(), pt) >= 0) {
          hull_.pop_back();
        }
        hull_.push_back(pt);
      }
      hull_.pop_back();
      std::reverse(hull_.begin(), hull_.end());
      const auto least = std::min_element(hull_.begin(), hull_.end(), [](const P2& a, const P2& b) {
        return a.x < b.x || (a.x == b.x && a.y < b.y);
      });
      std::rotate(hull_.begin(), least, hull_.end());
    }
    const double ox = static_cast<double>(cmin) - 1.0 + base;
    const double oy = static_cast<double>(rmin) - 1.0 + base;
    for (const P2& pt : hull_) {
      props_.convex_hull.emplace_back(0.5 * static_cast<double>(pt.x) + ox,
                                      0.5 * static_cast<double>(pt.y) + oy);
    }

    // poly2mask: scale by 5 and quantise (x -> round(5 (x - 1/2) + 1)), trace the closed
    // polygon through integer sub-pixel points, take its horizontal edges on pixel-centre
    // columns, and fill each column by the parity of the edges above each pixel centre.
    const Eigen::Index rows = rmax - rmin + 1;
    const Eigen::Index cols = cmax - cmin + 1;
    parity_.resize(rows, cols);
    parity_.setZero();
    for (std::size_t i = 0; i < hull_.size(); ++i) {
      const P2& a = hull_[i];
      const P2& b = hull_[(i + 1) % hull_.size()];
      toggle_edges(round_half(5 * a.x - 3), round_half(5 * a.y - 3), round_half(5 * b.x - 3),
                   round_half(5 * b.y - 3), rows, cols);
    }
    convex_image_.resize(rows, cols);
    std::int64_t count = 0;
    for (Eigen::Index r = 0; r < rows; ++r) {
      const std::uint8_t* above = r > 0 ? &convex_image_(r - 1, 0) : nullptr;
      const std::uint8_t* par = &parity_(r, 0);
      std::uint8_t* out = &convex_image_(r, 0);
      for (Eigen::Index c = 0; c < cols; ++c) {
        out[c] = static_cast<std::uint8_t>((above != nullptr ? above[c] : 0) ^ par[c]);
        count += out[c];
      }
    }
    props_.convex_area = static_cast<double>(count);
    props_.solidity = count > 0 ? props_.area / props_.convex_area : 0.0;
  }

  template <class D = void>
  void perimeter(const Deferred<MaskView, D>& mask) {
    static constexpr int kDr[8] = {0, -1, -1, -1, 0, 1, 1, 1};  // W NW N NE E SE S SW
    static constexpr int kDc[8] = {-1, -1, 0, 1, 1, 1, 0, -1};
    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    auto fg = [&](Eigen::Index r, Eigen::Index c) {
      return r >= 0 && r < rows && c >= 0 && c < cols && mask(r, c) != 0;
    };
    auto dir_of = [](int dr, int dc) {
      for (int k = 0; k < 8; ++k) {
        if (kDr[k] == dr && kDc[k] == dc) return k;
      }
      return 0;
    };
    const int n = components_.compute(mask, Connectivity::eight);
    const Labels& lab = components_.labels();
    seen_.assign(static_cast<std::size_t>(n) + 1, 0);
    double total = 0;
    for (Eigen::Index c0 = 0; c0 < cols; ++c0) {
      for (Eigen::Index r0 = 0; r0 < rows; ++r0) {
        const std::int32_t id = lab(r0, c0);
        if (id == 0 || seen_[static_cast<std::size_t>(id)] != 0) continue;
        seen_[static_cast<std::size_t>(id)] = 1;
        // Moore-neighbour trace from the first pixel in column order; we arrived from the west.
        boundary_.clear();
        boundary_.push_back({r0, c0});
        Eigen::Index r = r0, c = c0;
        int back = 0;
        Eigen::Index first_r = -1, first_c = -1;
        const std::size_t limit = 4 * static_cast<std::size_t>(rows * cols) + 8;
        while (boundary_.size() < limit) {
          int found = -1;
          for (int i = 1; i <= 8; ++i) {
            const int d = (back + i) % 8;
            if (fg(r + kDr[d], c + kDc[d])) {
              found = d;
              break;
            }
          }
          if (found < 0) break;  // isolated pixel
          const int prev = (found + 7) % 8;
          const Eigen::Index nr = r + kDr[found];
          const Eigen::Index nc = c + kDc[found];
          if (r == r0 && c == c0) {
            if (first_r < 0) {
              first_r = nr;
              first_c = nc;
            } else if (nr == first_r && nc == first_c) {
              break;  // about to repeat the first step: the boundary is closed
            }
          }
          back = dir_of(kDr[prev] - kDr[found], kDc[prev] - kDc[found]);
          r = nr;
          c = nc;
          boundary_.push_back({r, c});
        }
        const std::size_t steps = boundary_.size() - 1;
        if (steps < 2) continue;
        double even = 0, odd = 0, corners = 0;
        for (std::size_t i = 0; i < steps; ++i) {
          const std::size_t j = (i + 1) % steps;
          const auto dr = boundary_[i + 1].r - boundary_[i].r;
          const auto dc = boundary_[i + 1].c - boundary_[i].c;
          const auto dr2 = boundary_[j + 1].r - boundary_[j].r;
          const auto dc2 = boundary_[j + 1].c - boundary_[j].c;
          if (dr == 0 || dc == 0) {
            even += 1;
          } else {
            odd += 1;
          }
          if (dr * dr != dr2 * dr2 || dc * dc != dc2 * dc2) corners += 1;
        }
        total += 0.980 * even + 1.406 * odd - 0.091 * corners;
      }
    }
    props_.perimeter = total;
  }

  struct RC {
    Eigen::Index r, c;
  };

  RegionPropsOptions opt_;
  Components components_;
  RegionProps props_;
  std::vector<P2> points_, hull_;
  std::vector<Eigen::Index> row_first_, row_last_;
  std::vector<std::uint8_t> quad_;
  std::vector<std::uint64_t> packed_;
  static constexpr Eigen::Index kPackedCols = 62;
  Image<std::uint8_t> parity_;
  Mask convex_image_;
  std::vector<RC> boundary_;
  std::vector<std::uint8_t> seen_;
};

/// Allocating convenience: the descriptors of the non-zero pixels of `mask` as one region.
template <class D = void>
inline RegionProps region_props(const Deferred<MaskView, D>& mask,
                                const Deferred<RegionPropsOptions, D>& opt = {}) {
  RegionAnalyzer a(opt, mask.rows(), mask.cols());
  return a.compute(mask);
}

}  // namespace taxel::image
