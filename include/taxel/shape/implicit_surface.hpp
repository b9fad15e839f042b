// SPDX-License-Identifier: MIT
// A Gaussian-process implicit surface (Williams and Fitzgibbon, "Gaussian process implicit
// surfaces", Gaussian Processes in Practice workshop, 2006; Dragiev, Toussaint and Gienger,
// ICRA 2011): a field f over space, negative inside the object, zero on its surface, positive
// outside, about the signed distance near the surface. Each surface point p with outward normal
// n and variance s^2 along n gives three observations: f(p) = 0, f(p + d n) = d and
// f(p - d_in n) = -d_in (d and d_in the outside and inside offsets), each with noise
// variance s^2.
//
// The prior mean is the signed distance to a sphere, m(x) = |x - c| - r (Martens et al.,
// "Geometric priors for Gaussian process implicit surfaces", IEEE RA-L 2017), so that the
// field is a closed surface far from every touch; the process models f - m.
//
// Local experts (after Lee et al., "Online continuous mapping using Gaussian process implicit
// surfaces", ICRA 2019): space is cut into cubic cells of side L, the expert size.
// Expert c owns cell c and holds, in an exact Gaussian process of its own, the observations of
// the points within L/2 of its cell (a cube of side 2 L), so a point lives in the 8 experts
// around it, and adding it extends their Cholesky factors by one row per observation (O(n^2)
// each, no refit). A query at x uses the expert of its cell alone, except within b L of a
// cell face (b the blend width), where it blends the experts on both sides with smoothstep
// weights, w(t) = t^2 (3 - 2 t) across the band, a product over the three axes: a partition
// of unity with a continuous gradient. On average a query asks (1 + 2 b)^3 experts (1.7 at the
// default b = 0.1):
//   mean = m(x) + sum w_e mu_e(x),
//   variance = sum w_e (var_e(x) + mu_e(x)^2) - (sum w_e mu_e(x))^2   (the mixture's),
// an expert with no observations predicting the prior (mu = 0, var = k(0)). When every point
// lies within the lower half of one cell along each axis, the 8 experts around it hold them all
// and every query near them is the exact process.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "taxel/core/types.hpp"
#include "taxel/shape/gaussian_process.hpp"
#include "taxel/shape/grid.hpp"
#include "taxel/shape/kernels.hpp"

namespace taxel::shape {

/// Settings of an ImplicitSurface. Lengths in metres.
struct SurfaceConfig {
  /// L: spacing of the experts; each holds the points within L of it along every axis, so its
  /// size grows with L^2 of touched surface. Finite and > 0.
  double expert_size = 0.015;
  /// d: the outside observation's distance along the normal; 0 leaves it out. Finite and >= 0.
  double normal_offset = 0.003;
  /// d_in: the inside observation's distance against the normal; 0 leaves it out (with both
  /// 0 the normals go unused). Finite and >= 0. Near an edge the point d_in inside lies closer
  /// than d_in to the next face, so -d_in overstates its depth and pushes the surface out there.
  double inside_offset = 0.003;
  /// b: half-width of the band around a cell face where a query blends the experts on both
  /// sides, as a fraction of expert_size. In (0, 0.5].
  double blend = 0.1;
  /// Lower bound of each observation's noise standard deviation. Finite and > 0.
  double min_sigma = 0.2e-3;
  /// c: centre of the prior sphere.
  Vec3d prior_centre = Vec3d::Zero();
  /// r: radius of the prior sphere; 0 makes the prior the distance to c. Finite and >= 0.
  double prior_radius = 0.0;

  /// Throws std::invalid_argument naming the first setting out of range.
  void validate() const {
    const auto bad = [](const char* name, double v, const char* range) {
      throw std::invalid_argument(std::string("SurfaceConfig::") + name + " must be " + range +
                                  ", got " + std::to_string(v));
    };
    if (!(expert_size > 0.0) || !std::isfinite(expert_size))
      bad("expert_size", expert_size, "finite and > 0 [m]");
    if (!(blend > 0.0) || !(blend <= 0.5)) bad("blend", blend, "in (0, 0.5]");
    if (!(normal_offset >= 0.0) || !std::isfinite(normal_offset))
      bad("normal_offset", normal_offset, "finite and >= 0 [m]");
    if (!(inside_offset >= 0.0) || !std::isfinite(inside_offset))
      bad("inside_offset", inside_offset, "finite and >= 0 [m]");
    if (!(min_sigma > 0.0) || !std::isfinite(min_sigma))
      bad("min_sigma", min_sigma, "finite and > 0 [m]");
    if (!prior_centre.allFinite())
      throw std::invalid_argument("SurfaceConfig::prior_centre must be finite");
    if (!(prior_radius >= 0.0) || !std::isfinite(prior_radius))
      bad("prior_radius", prior_radius, "finite and >= 0 [m]");
  }
};

/// Integer coordinates of an expert or a cell.
using CellIndex = std::array<int, 3>;

/// A Gaussian-process implicit surface over local experts (see the file comment). Points are
/// added, moved and removed one at a time. Copyable; not thread-safe for writes, concurrent
/// const queries are safe.
template <Kernel K = Matern32>
class ImplicitSurface {
 public:
  /// One expert: its process and, per observation, the point it came from (id * 4 + kind,
  /// kind 0 on the surface, 1 outside, 2 inside, 3 free space).
  struct Expert {
    CellIndex cell{};                   ///< the cell it owns: [cell, cell + 1) * expert_size
    GaussianProcess<K> process;         ///< the process of its observations, minus the prior mean
    std::vector<std::uint64_t> owners;  ///< per observation: point id * 4 + kind
  };
  /// A stored surface point.
  struct Point {
    Vec3d position = Vec3d::Zero();  ///< [m]
    Vec3d normal = Vec3d::UnitZ();   ///< outward unit normal
    double variance = 0.0;           ///< along the normal [m^2], before the floor
    bool alive = false;              ///< false once erased
    /// A free-space point (insert_free): one observation of `value` at the position, no normal.
    bool free = false;
    double value = 0.0;  ///< the observed field at a free-space point [m]
  };

  /// Throws std::invalid_argument for an invalid configuration.
  explicit ImplicitSurface(const SurfaceConfig& config = {}, K kernel = K{})
      : config_(config), kernel_(std::move(kernel)) {
    config_.validate();
  }

  /// The settings.
  [[nodiscard]] const SurfaceConfig& config() const noexcept { return config_; }
  /// The kernel.
  [[nodiscard]] const K& kernel() const noexcept { return kernel_; }
  /// Number of stored points.
  [[nodiscard]] std::size_t size() const noexcept { return alive_; }
  /// Number of experts.
  [[nodiscard]] std::size_t expert_count() const noexcept { return experts_.size(); }
  /// Every expert.
  [[nodiscard]] const std::vector<Expert>& experts() const noexcept { return experts_; }
  /// Point `id` (ids count up from 0 and are never reused).
  [[nodiscard]] const Point& point(std::size_t id) const { return points_.at(id); }
  /// Ids handed out so far.
  [[nodiscard]] std::size_t id_count() const noexcept { return points_.size(); }

  /// Adds surface point `p` with outward normal `normal` (any length > 0) and variance
  /// `variance` [m^2] along it; returns its id, or nothing (and the surface unchanged) for a
  /// non-finite input, a zero normal or a negative variance.
  std::optional<std::size_t> insert(const Vec3d& p, const Vec3d& normal, double variance) {
    if (!valid(p, normal, variance)) return std::nullopt;
    const std::size_t id = points_.size();
    points_.push_back({p, normal.normalized(), variance, true});
    ++alive_;
    attach(id);
    return id;
  }

  /// Adds a free-space observation: the field at `x` is `value` (> 0: outside the object, e.g.
  /// a point the robot's finger passed through) with noise variance `variance` [m^2]. Returns
  /// its id, or nothing (and the surface unchanged) for a non-finite input or a negative
  /// variance. Erased like a surface point; update() refuses it.
  std::optional<std::size_t> insert_free(const Vec3d& x, double value, double variance) {
    if (!valid(x, Vec3d::UnitZ(), variance) || !std::isfinite(value)) return std::nullopt;
    const std::size_t id = points_.size();
    points_.push_back({x, Vec3d::Zero(), variance, true, true, value});
    ++alive_;
    attach(id);
    return id;
  }

  /// Moves point `id` to `p` with `normal` and `variance` (a fused point that moved). Returns
  /// false, and changes nothing, for an invalid input. Throws std::out_of_range for an id never
  /// handed out or erased.
  bool update(std::size_t id, const Vec3d& p, const Vec3d& normal, double variance) {
    check_id(id, "update");
    if (points_[id].free) return false;
    if (!valid(p, normal, variance)) return false;
    detach(id);
    points_[id] = {p, normal.normalized(), variance, true};
    attach(id);
    return true;
  }

  /// Removes point `id`. Throws std::out_of_range for an id never handed out or erased.
  void erase(std::size_t id) {
    check_id(id, "erase");
    detach(id);
    points_[id].alive = false;
    --alive_;
  }

  /// Replaces the prior sphere (every expert's targets change: O(n^2) per expert). Throws
  /// std::invalid_argument for a non-finite centre or a negative or non-finite radius.
  void set_prior(const Vec3d& centre, double radius) {
    SurfaceConfig c = config_;
    c.prior_centre = centre;
    c.prior_radius = radius;
    c.validate();
    config_ = c;
    all_changed_ = true;
    for (Expert& e : experts_) {
      Eigen::VectorXd y(static_cast<Eigen::Index>(e.owners.size()));
      for (std::size_t i = 0; i < e.owners.size(); ++i) {
        const auto [x, v] = observation(e.owners[i]);
        y(static_cast<Eigen::Index>(i)) = v - prior(x);
      }
      e.process.set_values(y);
    }
  }

  /// The prior mean m(x) = |x - c| - r.
  [[nodiscard]] double prior(const Vec3d& x) const {
    return (x - config_.prior_centre).norm() - config_.prior_radius;
  }

  /// Posterior mean of the field at `x` (1 to 8 experts, O(n) each).
  [[nodiscard]] double mean(const Vec3d& x) const {
    double out = prior(x);
    for_each_expert(x, [&](const Expert* e, double w, const Vec3d&) {
      if (e != nullptr) out += w * e->process.mean(x);
    });
    return out;
  }

  /// Posterior mean of the field at `x` and its gradient (1 to 8 experts, O(n) each).
  [[nodiscard]] double mean(const Vec3d& x, Vec3d& gradient) const {
    double out = 0.0;
    gradient.setZero();
    for_each_expert(x, [&](const Expert* e, double w, const Vec3d& dw) {
      if (e == nullptr) return;
      Vec3d g = Vec3d::Zero();
      const double mu = e->process.mean(x, g);
      out += w * mu;
      gradient += w * g + mu * dw;
    });
    const Vec3d d = x - config_.prior_centre;
    const double dn = d.norm();
    if (dn > 0.0) gradient += d / dn;
    return out + dn - config_.prior_radius;
  }

  /// Posterior mean, variance and the mean's gradient at `x` (1 to 8 experts, O(n^2) each).
  [[nodiscard]] FieldPrediction predict(const Vec3d& x) const {
    FieldPrediction out;
    double second = 0.0;
    for_each_expert(x, [&](const Expert* e, double w, const Vec3d& dw) {
      FieldPrediction p;
      p.variance = kernel_.variance();
      if (e != nullptr) p = e->process.predict(x);
      out.mean += w * p.mean;
      second += w * (p.variance + p.mean * p.mean);
      out.gradient += w * p.gradient + p.mean * dw;
    });
    out.variance = std::max(0.0, second - out.mean * out.mean);
    const Vec3d d = x - config_.prior_centre;
    const double dn = d.norm();
    out.mean += dn - config_.prior_radius;
    if (dn > 0.0) out.gradient += d / dn;
    return out;
  }

  /// The posterior mean at every node of `grid` (entry order of Grid). Throws
  /// std::invalid_argument for an invalid grid.
  [[nodiscard]] std::vector<double> sample(const Grid& grid) const {
    grid.validate();
    Eigen::Matrix3Xd nodes(3, static_cast<Eigen::Index>(grid.size()));
    for (int k = 0; k < grid.nodes[2]; ++k) {
      for (int j = 0; j < grid.nodes[1]; ++j) {
        for (int i = 0; i < grid.nodes[0]; ++i)
          nodes.col(static_cast<Eigen::Index>(grid.index(i, j, k))) = grid.node(i, j, k);
      }
    }
    std::vector<double> out(grid.size());
    evaluate(nodes, out.data(), nullptr);
    return out;
  }

  /// Posterior means, and variances when `variance` is not null, at the columns of `points`.
  /// Means alone are point by point (the kernel sums run on SIMD lanes); with variances the
  /// points are grouped by cell, and each expert around a cell predicts the group's points
  /// that blend it through one kernel matrix and one multi-column triangular solve.
  void evaluate(const Eigen::Ref<const Eigen::Matrix3Xd>& points, double* mean,
                double* variance) const {
    const Eigen::Index total = points.cols();
    if (variance == nullptr) {
      for (Eigen::Index q = 0; q < total; ++q) mean[q] = this->mean(Vec3d(points.col(q)));
      return;
    }
    // Grouped by cell; each of the 27 experts around a cell predicts, in one batch, the
    // group's points that blend it.
    std::vector<std::pair<std::uint64_t, Eigen::Index>> order(static_cast<std::size_t>(total));
    for (Eigen::Index q = 0; q < total; ++q)
      order[static_cast<std::size_t>(q)] = {key(cell_of(points.col(q))), q};
    std::sort(order.begin(), order.end());
    Eigen::Matrix3Xd subset;
    Eigen::VectorXd mu, var;
    std::vector<double> acc, second, w;
    std::vector<Eigen::Index> members;
    for (std::size_t first = 0; first < order.size();) {
      std::size_t last = first;
      while (last < order.size() && order[last].first == order[first].first) ++last;
      const std::size_t m = last - first;
      acc.assign(m, 0.0);
      second.assign(m, 0.0);
      w.resize(m);
      const CellIndex base = cell_of(points.col(order[first].second));
      for (int o = 0; o < 27; ++o) {
        const CellIndex c{base[0] + o % 3 - 1, base[1] + o / 3 % 3 - 1, base[2] + o / 9 - 1};
        members.clear();
        for (std::size_t q = 0; q < m; ++q) {
          w[q] = weight(points.col(order[first + q].second), c);
          if (w[q] > 0.0) members.push_back(static_cast<Eigen::Index>(q));
        }
        if (members.empty()) continue;
        const Expert* e = find(c);
        const bool empty = e == nullptr || e->process.size() == 0;
        if (empty && variance == nullptr) continue;
        const auto k = static_cast<Eigen::Index>(members.size());
        mu.resize(k);
        if (empty) {
          mu.setZero();
          var.setConstant(k, kernel_.variance());
        } else {
          subset.resize(3, k);
          for (Eigen::Index i = 0; i < k; ++i)
            subset.col(i) = points.col(
                order[first + static_cast<std::size_t>(members[static_cast<std::size_t>(i)])]
                    .second);
          e->process.predict(subset, mu, variance != nullptr ? &var : nullptr);
        }
        for (Eigen::Index i = 0; i < k; ++i) {
          const auto q = static_cast<std::size_t>(members[static_cast<std::size_t>(i)]);
          acc[q] += w[q] * mu(i);
          if (variance != nullptr) second[q] += w[q] * (var(i) + mu(i) * mu(i));
        }
      }
      for (std::size_t q = 0; q < m; ++q) {
        const auto at = static_cast<std::size_t>(order[first + q].second);
        mean[at] = acc[q] + prior(points.col(order[first + q].second));
        if (variance != nullptr) variance[at] = std::max(0.0, second[q] - acc[q] * acc[q]);
      }
      first = last;
    }
  }

  /// The experts whose observations changed since the last clear_changed() (keys of
  /// cell_key), unless every_expert_changed().
  [[nodiscard]] const std::vector<std::uint64_t>& changed_experts() const noexcept {
    return changed_;
  }
  /// True when every expert changed (the prior was replaced) since the last clear_changed().
  [[nodiscard]] bool every_expert_changed() const noexcept { return all_changed_; }
  /// Forgets which experts changed.
  void clear_changed() noexcept {
    changed_.clear();
    all_changed_ = false;
  }

  /// The posterior mean at the nodes of `grid` in cells next to an expert that changed since
  /// the last clear_changed() (all nodes when every expert changed), written into `field`, the
  /// grid's samples before those changes. Throws std::invalid_argument for a field that does
  /// not fit the grid.
  void resample(const Grid& grid, std::vector<double>& field) const {
    grid.validate();
    if (field.size() != grid.size())
      throw std::invalid_argument("ImplicitSurface::resample: the field does not fit the grid");
    if (all_changed_) {
      field = sample(grid);
      return;
    }
    if (changed_.empty()) return;
    std::unordered_set<std::uint64_t> cells;
    for (const std::uint64_t k : changed_) {
      const CellIndex c = experts_[lookup_.at(k)].cell;
      for (int i = 0; i < 27; ++i)
        cells.insert(key({c[0] + i % 3 - 1, c[1] + i / 3 % 3 - 1, c[2] + i / 9 - 1}));
    }
    std::vector<std::size_t> entries;
    for (int k = 0; k < grid.nodes[2]; ++k) {
      for (int j = 0; j < grid.nodes[1]; ++j) {
        for (int i = 0; i < grid.nodes[0]; ++i) {
          if (cells.count(key(cell_of(grid.node(i, j, k)))) != 0)
            entries.push_back(grid.index(i, j, k));
        }
      }
    }
    Eigen::Matrix3Xd nodes(3, static_cast<Eigen::Index>(entries.size()));
    for (std::size_t e = 0; e < entries.size(); ++e) {
      const std::size_t at = entries[e];
      const int i = static_cast<int>(at % std::size_t(grid.nodes[0]));
      const int j = static_cast<int>(at / std::size_t(grid.nodes[0]) % std::size_t(grid.nodes[1]));
      const int k =
          static_cast<int>(at / (std::size_t(grid.nodes[0]) * std::size_t(grid.nodes[1])));
      nodes.col(static_cast<Eigen::Index>(e)) = grid.node(i, j, k);
    }
    std::vector<double> values(entries.size());
    evaluate(nodes, values.data(), nullptr);
    for (std::size_t e = 0; e < entries.size(); ++e) field[entries[e]] = values[e];
  }

  /// A key unique to each cell within 2^20 cells of the origin.
  [[nodiscard]] static std::uint64_t cell_key(const CellIndex& c) noexcept {
    const auto part = [](int v) { return std::uint64_t(std::uint32_t(v) & 0x1FFFFFu); };
    return part(c[0]) | (part(c[1]) << 21) | (part(c[2]) << 42);
  }

  /// The expert at `cell`, or nullptr.
  [[nodiscard]] const Expert* find(const CellIndex& cell) const {
    const auto it = lookup_.find(key(cell));
    return it == lookup_.end() ? nullptr : &experts_[it->second];
  }
  /// The cell of side L holding `x`; its expert answers queries at x away from the faces.
  [[nodiscard]] CellIndex cell_of(const Vec3d& x) const {
    const Vec3d u = x / config_.expert_size;
    return {static_cast<int>(std::floor(u[0])), static_cast<int>(std::floor(u[1])),
            static_cast<int>(std::floor(u[2]))};
  }
  /// The expert whose cell holds `x` (the same as cell_of).
  [[nodiscard]] CellIndex nearest_expert(const Vec3d& x) const { return cell_of(x); }
  /// The most observations any expert holds.
  [[nodiscard]] std::size_t largest_expert() const noexcept {
    std::size_t n = 0;
    for (const Expert& e : experts_) n = std::max(n, e.process.size());
    return n;
  }
  /// Position and value of an observation, from its owner code (id * 4 + kind; kind 3 is a
  /// free-space point's).
  [[nodiscard]] std::pair<Vec3d, double> observation(std::uint64_t owner) const {
    const Point& p = points_[owner / 4];
    const double d = config_.normal_offset;
    switch (owner % 4) {
      case 3:
        return {p.position, p.value};
      case 1:
        return {p.position + d * p.normal, d};
      case 2:
        return {p.position - config_.inside_offset * p.normal, -config_.inside_offset};
      default:
        return {p.position, 0.0};
    }
  }
  /// Noise variance of point `id`'s observations: its variance, floored at min_sigma^2.
  [[nodiscard]] double noise(std::size_t id) const {
    return std::max(points_.at(id).variance, config_.min_sigma * config_.min_sigma);
  }

  /// Calls f(expert or nullptr, weight, gradient of the weight, cell) for each expert a query
  /// at `x` blends (1 to 8; see the file comment).
  template <class F>
  void for_each_expert(const Vec3d& x, F&& f) const {
    std::array<std::array<int, 2>, 3> cell{};
    std::array<std::array<double, 2>, 3> w{}, dw{};
    std::array<int, 3> count{};
    for (int a = 0; a < 3; ++a) axis(x[a], cell[a], w[a], dw[a], count[a]);
    for (int i = 0; i < count[0]; ++i) {
      for (int j = 0; j < count[1]; ++j) {
        for (int k = 0; k < count[2]; ++k) {
          const CellIndex c{cell[0][i], cell[1][j], cell[2][k]};
          const double wx = w[0][i], wy = w[1][j], wz = w[2][k];
          const Vec3d g(dw[0][i] * wy * wz, wx * dw[1][j] * wz, wx * wy * dw[2][k]);
          if constexpr (std::is_invocable_v<F, const Expert*, double, const Vec3d&,
                                            const CellIndex&>) {
            f(find(c), wx * wy * wz, g, c);
          } else {
            f(find(c), wx * wy * wz, g);
          }
        }
      }
    }
  }

  /// The weight of the expert at `cell` in a query at `x` (0 when it takes no part).
  [[nodiscard]] double weight(const Vec3d& x, const CellIndex& c) const {
    double out = 1.0;
    for (int a = 0; a < 3; ++a) {
      std::array<int, 2> cells{};
      std::array<double, 2> w{}, dw{};
      int count = 0;
      axis(x[a], cells, w, dw, count);
      double wa = 0.0;
      for (int i = 0; i < count; ++i)
        wa += cells[static_cast<std::size_t>(i)] == c[static_cast<std::size_t>(a)]
                  ? w[static_cast<std::size_t>(i)]
                  : 0.0;
      out *= wa;
    }
    return out;
  }

 private:
  static std::uint64_t key(const CellIndex& c) noexcept { return cell_key(c); }
  // Along one axis at coordinate v: the cells a query blends (1 or 2), their smoothstep
  // weights and the weights' derivatives.
  void axis(double v, std::array<int, 2>& cells, std::array<double, 2>& w,
            std::array<double, 2>& dw, int& count) const {
    const double L = config_.expert_size, b = config_.blend;
    const double u = v / L;
    const double c = std::floor(u);
    const double f = u - c;
    const int ci = static_cast<int>(c);
    const auto step = [&](double t, double& value, double& slope) {
      value = t * t * (3.0 - 2.0 * t);
      slope = 6.0 * t * (1.0 - t) / (2.0 * b * L);
    };
    if (f < b || f > 1.0 - b) {
      const int lo = f < b ? ci - 1 : ci;
      double hi_w = 0.0, hi_d = 0.0;
      step(f < b ? (f + b) / (2.0 * b) : (f - 1.0 + b) / (2.0 * b), hi_w, hi_d);
      cells = {lo, lo + 1};
      w = {1.0 - hi_w, hi_w};
      dw = {-hi_d, hi_d};
      count = 2;
    } else {
      cells = {ci, ci};
      w = {1.0, 0.0};
      dw = {0.0, 0.0};
      count = 1;
    }
  }
  // The experts that hold a point at p: per axis the two whose cells lie within L/2.
  CellIndex lower_holder(const Vec3d& p) const {
    const Vec3d u = p / config_.expert_size + Vec3d::Constant(0.5);
    return {static_cast<int>(std::floor(u[0])) - 1, static_cast<int>(std::floor(u[1])) - 1,
            static_cast<int>(std::floor(u[2])) - 1};
  }
  bool valid(const Vec3d& p, const Vec3d& normal, double variance) const {
    return p.allFinite() && normal.allFinite() && normal.norm() > 1e-12 && variance >= 0.0 &&
           std::isfinite(variance) &&
           // Beyond 2^20 cells the expert keys would wrap.
           (p / config_.expert_size).cwiseAbs().maxCoeff() < double(1 << 20) - 2;
  }
  void check_id(std::size_t id, const char* what) const {
    if (id >= points_.size() || !points_[id].alive) {
      throw std::out_of_range(std::string("ImplicitSurface::") + what + ": no point " +
                              std::to_string(id));
    }
  }
  Expert& expert(const CellIndex& cell) {
    const auto [it, added] = lookup_.try_emplace(key(cell), experts_.size());
    if (added) experts_.push_back({cell, GaussianProcess<K>(kernel_), {}});
    mark(it->first);
    return experts_[it->second];
  }
  void mark(std::uint64_t k) {
    if (!all_changed_ && std::find(changed_.begin(), changed_.end(), k) == changed_.end())
      changed_.push_back(k);
  }
  bool has_kind(int kind) const {
    return kind == 0 || (kind == 1 && config_.normal_offset > 0.0) ||
           (kind == 2 && config_.inside_offset > 0.0);
  }
  void attach(std::size_t id) {
    const CellIndex base = lower_holder(points_[id].position);
    const double nv = noise(id);
    for (int c = 0; c < 8; ++c) {
      Expert& e = expert({base[0] + (c & 1), base[1] + ((c >> 1) & 1), base[2] + ((c >> 2) & 1)});
      for (int kind = 0; kind < 3; ++kind) {
        if (!has_kind(kind)) continue;
        const std::uint64_t owner =
            std::uint64_t(id) * 4 + std::uint64_t(points_[id].free ? 3 : kind);
        if (points_[id].free && kind > 0) break;
        const auto [x, v] = observation(owner);
        if (e.process.add(x, v - prior(x), nv)) e.owners.push_back(owner);
      }
    }
  }
  void detach(std::size_t id) {
    const CellIndex base = lower_holder(points_[id].position);
    for (int c = 0; c < 8; ++c) {
      const auto it = lookup_.find(
          key({base[0] + (c & 1), base[1] + ((c >> 1) & 1), base[2] + ((c >> 2) & 1)}));
      if (it == lookup_.end()) continue;
      Expert& e = experts_[it->second];
      mark(it->first);
      for (std::size_t i = e.owners.size(); i-- > 0;) {
        if (e.owners[i] / 4 != id) continue;
        e.process.remove(i);
        e.owners.erase(e.owners.begin() + static_cast<std::ptrdiff_t>(i));
      }
    }
  }

  SurfaceConfig config_;
  K kernel_;
  std::vector<Point> points_;
  std::size_t alive_ = 0;
  std::vector<Expert> experts_;
  std::unordered_map<std::uint64_t, std::size_t> lookup_;
  std::vector<std::uint64_t> changed_;
  bool all_changed_ = true;
};

}  // namespace taxel::shape
