// SPDX-License-Identifier: MIT
// A static uniform grid over a fixed point set: a dense array of cell starts over the points'
// bounding box and the points sorted by cell (CSR layout). Nearest-neighbour queries search
// shells of cells outward from the query's cell and stop as soon as no unvisited cell can hold
// a closer point, so answers are exact. Near the stored surface a query visits about 27 cells
// in contiguous memory, a few times faster than a kd-tree; far from the box it falls back to
// enumerating shells up to the query radius. Built for ICP targets (registration::Target).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/types.hpp"
#include "taxel/index/concepts.hpp"

namespace taxel::index {

/// Static exact index on a uniform grid; point i has id i. Models SpatialIndex.
/// Const queries may run concurrently.
/// Immutable after construction: concurrent queries are safe.
template <Scalar S>
class UniformGrid {
 public:
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Build parameters.
  struct Config {
    /// Cell edge [m]; 0 picks `spacing_factor` times the points' mean nearest-neighbour
    /// spacing.
    S cell = S(0);
    /// Largest number of cells; the cell grows until the grid fits, >= 1.
    std::size_t max_cells = std::size_t{1} << 24;
    /// The automatic cell in mean spacings, > 0. Larger cells hold more points but answer
    /// more queries from the 2 x 2 x 2 block: make them larger than typical query distances.
    double spacing_factor = 2.0;
  };

  /// Builds the grid. Throws std::invalid_argument for non-finite points, a negative or
  /// non-finite cell, or more than 2^32 - 1 points.
  explicit UniformGrid(std::vector<Vec3<S>> points, const Config& config = {})
      : points_(std::move(points)) {
    if (points_.size() >= std::numeric_limits<std::uint32_t>::max()) {
      throw std::invalid_argument("UniformGrid: more than 2^32 - 1 points");
    }
    if (!(config.cell >= S(0)) || !std::isfinite(config.cell) || config.max_cells == 0) {
      throw std::invalid_argument(
          "UniformGrid::Config: cell must be finite and >= 0, "
          "max_cells >= 1");
    }
    for (std::size_t i = 0; i < points_.size(); ++i) {
      if (!points_[i].allFinite()) {
        throw std::invalid_argument("UniformGrid: point " + std::to_string(i) + " is not finite");
      }
    }
    if (points_.empty()) return;
    lo_ = points_.front();
    Vec3<S> hi = lo_;
    for (const auto& p : points_) {
      lo_ = lo_.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    if (!(config.spacing_factor > 0.0) || !std::isfinite(config.spacing_factor)) {
      throw std::invalid_argument("UniformGrid::Config: spacing_factor must be finite and > 0");
    }
    // The box is measured in double (no overflow for float points); a box too wide for S to
    // hold its extent or a cell (points near +-max) is refused rather than looped over.
    const Vec3d extent = hi.template cast<double>() - lo_.template cast<double>();
    const double widest = extent.maxCoeff();
    if (!std::isfinite(widest) ||
        widest > 0.25 * static_cast<double>(std::numeric_limits<S>::max())) {
      throw std::invalid_argument(
          "UniformGrid: the points span " + std::to_string(widest) +
          " along one axis, too wide to grid; coordinates must stay within +-" +
          std::to_string(0.125 * static_cast<double>(std::numeric_limits<S>::max())));
    }
    double cell = config.cell > S(0) ? static_cast<double>(config.cell)
                                     : config.spacing_factor * mean_spacing();
    // A cell at least a 2^-20 of the widest extent keeps every cell coordinate far inside int
    // range; finer cells would exceed max_cells anyway.
    cell = std::max({cell, widest * 0x1p-20, static_cast<double>(std::numeric_limits<S>::min())});
    for (;;) {
      std::array<double, 3> n{};
      double total = 1.0;
      for (int a = 0; a < 3; ++a) {
        // One empty cell of padding on each side: queries just outside the points' box still
        // take the fast path.
        n[static_cast<std::size_t>(a)] = std::floor(static_cast<double>(extent[a]) / cell) + 3.0;
        total *= n[static_cast<std::size_t>(a)];
      }
      if (total <= static_cast<double>(config.max_cells)) {
        for (int a = 0; a < 3; ++a)
          dims_[static_cast<std::size_t>(a)] = static_cast<int>(n[static_cast<std::size_t>(a)]);
        break;
      }
      // Grows by at least 1 %; `total` is finite, as extent / cell <= 2^20 per axis.
      cell *= std::cbrt(total / static_cast<double>(config.max_cells)) * 1.01;
    }
    cell_ = static_cast<S>(cell);
    inv_cell_ = S(1) / cell_;
    lo_ -= Vec3<S>::Constant(cell_);
    const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
    start_.assign(cells + 1, 0);
    std::vector<std::uint32_t> cell_of(points_.size());
    for (std::size_t i = 0; i < points_.size(); ++i) {
      const auto c = cell_index(coord(points_[i]));
      cell_of[i] = static_cast<std::uint32_t>(c);
      ++start_[c + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
    order_.resize(points_.size());
    sx_.resize(points_.size());
    sy_.resize(points_.size());
    sz_.resize(points_.size());
    std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < points_.size(); ++i) {  // ids ascend within each cell
      const std::uint32_t slot = fill[cell_of[i]]++;
      order_[slot] = static_cast<PointId>(i);
      sx_[slot] = points_[i].x();
      sy_[slot] = points_[i].y();
      sz_[slot] = points_[i].z();
    }
  }

  /// Number of points.
  [[nodiscard]] std::size_t size() const noexcept { return points_.size(); }
  /// All points, indexed by id.
  [[nodiscard]] const std::vector<Vec3<S>>& points() const noexcept { return points_; }
  /// The cell edge [m].
  [[nodiscard]] S cell() const noexcept { return cell_; }
  /// Heap bytes held.
  [[nodiscard]] std::size_t memory_bytes() const noexcept {
    return points_.capacity() * sizeof(Vec3<S>) +
           (sx_.capacity() + sy_.capacity() + sz_.capacity()) * sizeof(S) +
           start_.capacity() * sizeof(std::uint32_t) + order_.capacity() * sizeof(PointId);
  }

  /// The closest point within distance r of q (ties by id), if any. A point whose squared
  /// distance overflows (farther than about 1e154 in double) is never returned.
  [[nodiscard]] std::optional<Neighbor<S>> nearest_within(const Vec3<S>& q, S r) const {
    if (points_.empty() || !q.allFinite() || !(r >= S(0))) return std::nullopt;
    Neighbor<S> best{0, r * r};
    bool found = false;
    const auto keep = [&](PointId id, S d2) {
      if (!(d2 < std::numeric_limits<S>::infinity())) return;  // an overflowing distance
      if (d2 < best.squared_distance || (d2 == best.squared_distance && (!found || id < best.id))) {
        best = {id, d2};
        found = true;
      }
    };
    // Fast path: the 2 x 2 x 2 block of cells nearest to q. Every point outside it is at
    // least `margin` away, so a strictly closer answer is final.
    const S margin = visit_block(q, keep);
    if (found) {
      if (best.squared_distance < margin * margin) return best;
      // The block's best bounds the answer: the rows of cells meeting the ball it bounds hold
      // every closer point (a query a cell or two off its surface, as at the start of an
      // alignment).
      if (scan_ball(q, best.squared_distance, best.id, kScanCells)) return best;
    } else if (margin > S(0)) {
      // An empty block: the cells meeting the ball of two cells (or r, if smaller) around q.
      // A point found there is the answer; none means none within r when r is that small.
      const S reach = std::min(r, S(2) * cell_);
      S d2 = std::min(reach * reach, std::numeric_limits<S>::max());
      PointId id = kNone;
      if (scan_ball(q, d2, id, kScanCells)) {
        if (id != kNone) return Neighbor<S>{id, d2};
        if (r <= S(2) * cell_) return std::nullopt;
      }
    }
    // Wider: shells of cells outward from q, from the best so far (revisiting a point changes
    // nothing), until no unvisited cell can hold a closer point.
    search(q, r, keep, [&] { return best.squared_distance; });
    return found ? std::optional<Neighbor<S>>(best) : std::nullopt;
  }

  /// The same answer as nearest_within(q, r), searched from a hint: any point id whose
  /// distance to q bounds the answer's. Only the cells meeting the ball of that radius are
  /// read, so a hint near the answer (the previous iteration's match in ICP, where the query
  /// moved a little) reads a few cells and never the outward shells. A hint farther
  /// than r, or out of range, falls back to the search without one.
  [[nodiscard]] std::optional<Neighbor<S>> nearest_within(const Vec3<S>& q, S r,
                                                          PointId hint) const {
    if (points_.empty() || !q.allFinite() || !(r >= S(0)) || hint >= points_.size()) {
      return nearest_within(q, r);
    }
    const S h2 = squared_distance(points_[hint], q);
    if (!(h2 <= r * r)) return nearest_within(q, r);
    S best_d2 = h2;
    PointId best_id = hint;
    // A ball over more than three cells per axis goes the general way: a hint that far says
    // little about where the answer lies, and the 2 x 2 x 2 block often settles it.
    if (!scan_ball(q, best_d2, best_id, 3)) return nearest_within(q, r);
    return Neighbor<S>{best_id, best_d2};
  }

  /// The answer of nearest_within(q, r, hint), and how far q may move and keep it.
  struct Stable {
    Neighbor<S> nearest;  ///< The nearest point.
    /// Every query within this distance of q [m] has the same nearest point (not strictly
    /// tied with another), allowing for the rounding of the distances: with d the answer's
    /// distance and c a lower bound on every other point's, a query moved by less than
    /// (c - d) / 2 stays closer to the answer than to any other point (triangle inequality).
    /// 0 when no such bound was worked out.
    double radius = 0.0;
  };

  /// nearest_within(q, r, hint), and the radius of the ball around q whose queries share its
  /// answer. The other points' lower bound c is the nearer of the second-closest point read
  /// and the faces of the box of cells read, so this costs one more comparison per point.
  /// ICP keeps a source point's match while the point moves less than that radius, without
  /// searching: the same correspondences as a search.
  [[nodiscard]] std::optional<Stable> nearest_stable(const Vec3<S>& q, S r, PointId hint) const {
    if (!points_.empty() && q.allFinite() && r >= S(0) && hint < points_.size()) {
      const S h2 = squared_distance(points_[hint], q);
      if (h2 <= r * r) {
        S best_d2 = h2, second_d2 = std::numeric_limits<S>::infinity();
        PointId best_id = hint;
        double face = 0.0;
        if (scan_ball(q, best_d2, best_id, 3, &second_d2, &face)) {
          // Rounding: the cell coordinates and every distance are within a few ulps of S of
          // the coordinates' magnitudes (query, grid origin, distances).
          const double best = std::sqrt(static_cast<double>(best_d2));
          const double clear = std::min(std::sqrt(static_cast<double>(second_d2)), face);
          const double scale = q.template cast<double>().cwiseAbs().sum() +
                               lo_.template cast<double>().cwiseAbs().sum() +
                               static_cast<double>(cell_) + clear;
          const double allowance =
              16.0 * static_cast<double>(std::numeric_limits<S>::epsilon()) * scale;
          const double radius = 0.5 * (clear - best) - allowance;
          return Stable{{best_id, best_d2}, std::isfinite(radius) ? std::max(radius, 0.0) : 0.0};
        }
      }
    }
    const auto nb = nearest_within(q, r, hint);
    return nb ? std::optional<Stable>(Stable{*nb, 0.0}) : std::nullopt;
  }

  /// The min(k, size()) closest points, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> knn(const Vec3<S>& q, std::size_t k) const {
    k = std::min(k, size());
    std::vector<Neighbor<S>> out;
    if (k == 0 || !q.allFinite()) return out;
    out.reserve(k + 1);
    const S inf = std::numeric_limits<S>::infinity();
    search(
        q, inf,
        [&](PointId id, S d2) {
          const Neighbor<S> n{id, d2};
          if (out.size() == k && !closer(n, out.back())) return;
          out.insert(std::upper_bound(out.begin(), out.end(), n, closer<S>), n);
          if (out.size() > k) out.pop_back();
        },
        [&] { return out.size() < k ? inf : out.back().squared_distance; });
    return out;
  }

  /// Every point within distance r of q, ordered by `closer`.
  [[nodiscard]] std::vector<Neighbor<S>> within(const Vec3<S>& q, S r) const {
    std::vector<Neighbor<S>> out;
    if (points_.empty() || !q.allFinite() || !(r >= S(0))) return out;
    const S r2 = r * r;
    search(
        q, r,
        [&](PointId id, S d2) {
          if (d2 <= r2) out.push_back({id, d2});
        },
        [&] { return r2; });
    std::sort(out.begin(), out.end(), closer<S>);
    return out;
  }

 private:
  // The closest point to q among those within sqrt(best_d2) of it, ties by id, starting from
  // (best_d2, best_id): a point at that distance, or kNone for a bare radius. Reads the rows
  // of the cells meeting that ball (padded against the rounding of cell coordinates).
  // False, with nothing changed, when the ball spans more than max_cells cells on an axis.
  // With `second`, also the smallest squared distance of the other points read, and in `face`
  // the distance [m] from q to the nearest face of the box of cells read that borders cells
  // of the grid (infinite when the box is the whole grid).
  bool scan_ball(const Vec3<S>& q, S& best_d2, PointId& best_id, int max_cells, S* second = nullptr,
                 double* face = nullptr) const {
    const double reach =
        std::sqrt(static_cast<double>(best_d2)) / static_cast<double>(cell_) + 1e-3;
    std::array<int, 3> lo{}, hi{};
    const Vec3<S> c = coord(q);
    for (int a = 0; a < 3; ++a) {
      const auto ua = static_cast<std::size_t>(a);
      const double x = static_cast<double>(c[a]);
      const double top = dims_[ua] - 1;
      const double l = std::floor(x - reach), h = std::floor(x + reach);
      if (!(h - l < double(max_cells))) return false;
      lo[ua] = static_cast<int>(std::clamp(l, 0.0, top));
      hi[ua] = static_cast<int>(std::clamp(h, 0.0, top));
    }
    if (second == nullptr) {
      scan_rows<false>(q, lo, hi, best_d2, best_id, nullptr);
      return true;
    }
    scan_rows<true>(q, lo, hi, best_d2, best_id, second);
    // Every cell outside the box lies beyond one of its faces, along that face's axis (q
    // itself lies inside the box along any axis whose face borders grid cells).
    double f = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      const auto ua = static_cast<std::size_t>(a);
      const double x = static_cast<double>(c[a]);
      if (lo[ua] > 0) f = std::min(f, x - lo[ua]);
      if (hi[ua] < dims_[ua] - 1) f = std::min(f, hi[ua] + 1 - x);
    }
    *face = std::max(f, 0.0) * static_cast<double>(cell_);
    return true;
  }

  // The closest point to q in the box of cells [lo, hi] (inclusive, inside the grid) that beats
  // (best_d2, best_id), ties by id, selected without branches: which point of a row wins is
  // data, and a branch on it mispredicts often. With kSecond, also the smallest squared
  // distance of the points read other than the winner (into *second, which starts it).
  template <bool kSecond>
  void scan_rows(const Vec3<S>& q, const std::array<int, 3>& lo, const std::array<int, 3>& hi,
                 S& best_d2, PointId& best_id, S* second) const {
    S d2_best = best_d2;
    PointId id_best = best_id;
    S d2_second = kSecond ? *second : S(0);
    for (int z = lo[2]; z <= hi[2]; ++z) {
      for (int y = lo[1]; y <= hi[1]; ++y) {
        const std::size_t row = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0];
        for (std::uint32_t s = start_[row + lo[0]], e = start_[row + hi[0] + 1]; s < e; ++s) {
          const S d2 = sorted_distance(s, q);
          const PointId id = order_[s];
          const bool better = (d2 < d2_best) | ((d2 == d2_best) & (id < id_best));
          if constexpr (kSecond) {
            // A displaced winner is a real point (the hint or one read); the winner itself,
            // read again, is not another point.
            const S other = id == id_best ? d2_second : std::min(d2_second, d2);
            d2_second = better ? d2_best : other;
          }
          d2_best = better ? d2 : d2_best;
          id_best = better ? id : id_best;
        }
      }
    }
    best_d2 = d2_best;
    best_id = id_best;
    if constexpr (kSecond) *second = d2_second;
  }

  // The mean nearest-neighbour distance of up to 64 evenly spread points (brute force).
  [[nodiscard]] double mean_spacing() const {
    const std::size_t n = points_.size();
    const std::size_t samples = std::min<std::size_t>(n, 64);
    double sum = 0.0;
    std::size_t counted = 0;
    for (std::size_t s = 0; s < samples; ++s) {
      const std::size_t i = s * n / samples;
      S best = std::numeric_limits<S>::infinity();
      for (std::size_t j = 0; j < n; ++j) {
        const S d2 = squared_distance(points_[i], points_[j]);
        if (j != i && d2 > S(0)) best = std::min(best, d2);
      }
      if (std::isfinite(static_cast<double>(best))) {
        sum += std::sqrt(static_cast<double>(best));
        ++counted;
      }
    }
    return counted == 0 ? 1.0 : std::max(sum / static_cast<double>(counted), 1e-9);
  }

  [[nodiscard]] Vec3<S> coord(const Vec3<S>& p) const { return (p - lo_) * inv_cell_; }
  [[nodiscard]] std::size_t cell_index(const Vec3<S>& c) const {
    std::array<int, 3> i{};
    for (int a = 0; a < 3; ++a) {
      // Clamped in floating point first: huge or NaN coordinates never reach the int cast.
      const double top = dims_[static_cast<std::size_t>(a)] - 1;
      const double x = std::floor(static_cast<double>(c[a]));
      i[static_cast<std::size_t>(a)] = static_cast<int>(x >= 0.0 ? std::min(x, top) : 0.0);
    }
    return (static_cast<std::size_t>(i[2]) * dims_[1] + i[1]) * dims_[0] + i[0];
  }

  // Visits the points of shells of cells around q, ring 0 (q's cell) outwards, calling
  // visit(id, d2) for each; stops when bound() (the current squared search radius, <= r^2 or
  // infinite) is below the squared distance from q to every unvisited cell, or r is exceeded.
  template <class Visit, class Bound>
  void search(const Vec3<S>& q, S r, Visit&& visit, Bound&& bound) const {
    // Cell coordinates, clamped far outside the grid so that they fit an int.
    const Vec3<S> c = coord(q).cwiseMax(S(-1e8)).cwiseMin(S(1e8));
    std::array<int, 3> home{};
    // Distance (in cells) from q to the box of cells [home - k, home + k] per axis is at
    // least k - frac..., tracked as the gap to the nearest unvisited layer.
    double inner = std::numeric_limits<double>::infinity();  // q to its cell's nearest face
    for (int a = 0; a < 3; ++a) {
      const double x = static_cast<double>(c[a]);
      const int cell = static_cast<int>(std::floor(x));
      home[static_cast<std::size_t>(a)] = cell;
      inner = std::min(inner, std::min(x - cell, cell + 1 - x));
    }
    // Cells outside the grid are empty: rings before `first` and after `last` hold nothing.
    int first = 0;
    int last = 0;
    for (int a = 0; a < 3; ++a) {
      const int h = home[static_cast<std::size_t>(a)];
      const int d = dims_[static_cast<std::size_t>(a)];
      first = std::max(first, std::max(-h, h - (d - 1)));
      last = std::max(last, std::max(h, d - 1 - h));
    }
    const double cell = static_cast<double>(cell_);
    const double r_cells = std::isinf(static_cast<double>(r))
                               ? std::numeric_limits<double>::infinity()
                               : static_cast<double>(r) / cell;
    for (int k = first; k <= last; ++k) {
      // Every point in ring k is at least (k - 1 + inner) cells away (0 for k = 0).
      const double gap = k == 0 ? 0.0 : (k - 1 + std::max(inner, 0.0));
      if (gap > r_cells) return;
      const double g = gap * cell;
      if (k > 0 && static_cast<double>(bound()) < g * g) return;
      visit_ring(home, k, q, visit);
    }
  }

  // Visits the 2 x 2 x 2 block of cells nearest to q (clipped to the grid); returns the
  // distance from q to the nearest face of the block that borders unvisited cells (0 when q is
  // outside the grid: no fast path).
  template <class Visit>
  S visit_block(const Vec3<S>& q, Visit& visit) const {
    const Vec3<S> c = coord(q);
    std::array<int, 3> lo{};
    S margin = std::numeric_limits<S>::infinity();
    for (int a = 0; a < 3; ++a) {
      const S x = c[a];
      if (!(x >= S(0) && x < S(dims_[static_cast<std::size_t>(a)]))) return S(0);
      const int cell = static_cast<int>(x);
      const int first = x - S(cell) < S(0.5) ? cell - 1 : cell;  // block spans [first, first + 2)
      lo[static_cast<std::size_t>(a)] = first;
      // Distance to each block face, unless the grid ends there (nothing lies beyond).
      if (first > 0) margin = std::min(margin, x - S(first));
      if (first + 2 < dims_[static_cast<std::size_t>(a)])
        margin = std::min(margin, S(first + 2) - x);
    }
    const int x0 = std::max(lo[0], 0), x1 = std::min(lo[0] + 1, dims_[0] - 1);
    for (int z = std::max(lo[2], 0); z <= std::min(lo[2] + 1, dims_[2] - 1); ++z) {
      for (int y = std::max(lo[1], 0); y <= std::min(lo[1] + 1, dims_[1] - 1); ++y) {
        const std::size_t row = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0];
        visit_cells(row + x0, row + x1 + 1, q, visit);
      }
    }
    return margin * cell_;
  }

  template <class Visit>
  void visit_ring(const std::array<int, 3>& h, int k, const Vec3<S>& q, Visit& visit) const {
    const int z0 = std::max(h[2] - k, 0), z1 = std::min(h[2] + k, dims_[2] - 1);
    const int y0 = std::max(h[1] - k, 0), y1 = std::min(h[1] + k, dims_[1] - 1);
    const int x0 = std::max(h[0] - k, 0), x1 = std::min(h[0] + k, dims_[0] - 1);
    for (int z = z0; z <= z1; ++z) {
      const bool zedge = z == h[2] - k || z == h[2] + k;
      for (int y = y0; y <= y1; ++y) {
        const bool yedge = zedge || y == h[1] - k || y == h[1] + k;
        const std::size_t row = (static_cast<std::size_t>(z) * dims_[1] + y) * dims_[0];
        if (yedge) {
          visit_cells(row + x0, row + x1 + 1, q, visit);
        } else {  // interior rows of the shell: only the two end cells
          const int left = h[0] - k;
          const int right = h[0] + k;
          if (left >= 0 && left < dims_[0]) visit_cells(row + left, row + left + 1, q, visit);
          if (right >= 0 && right < dims_[0] && k > 0) {
            visit_cells(row + right, row + right + 1, q, visit);
          }
        }
      }
    }
  }

  template <class Visit>
  void visit_cells(std::size_t from, std::size_t to, const Vec3<S>& q, Visit& visit) const {
    for (std::uint32_t s = start_[from], e = start_[to]; s < e; ++s) {
      visit(order_[s], sorted_distance(s, q));
    }
  }

  // Squared distance from q to the sorted point s, as squared_distance computes it (the same
  // bits as every other index).
  S sorted_distance(std::uint32_t s, const Vec3<S>& q) const noexcept {
    const S dx = sx_[s] - q.x(), dy = sy_[s] - q.y(), dz = sz_[s] - q.z();
    return dx * dx + dy * dy + dz * dz;
  }

  std::vector<Vec3<S>> points_;
  std::vector<S> sx_, sy_, sz_;       // the points' coordinates in cell order
  std::vector<PointId> order_;        // id of each sorted point
  std::vector<std::uint32_t> start_;  // CSR offsets, one per cell + 1
  std::array<int, 3> dims_{1, 1, 1};
  Vec3<S> lo_ = Vec3<S>::Zero();
  S cell_ = S(1);
  S inv_cell_ = S(1);
  static constexpr int kScanCells = 7;  // widest ball read without a hint, cells per axis
  static constexpr PointId kNone = std::numeric_limits<PointId>::max();  // no point yet
};

}  // namespace taxel::index
