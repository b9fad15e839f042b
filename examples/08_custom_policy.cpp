// SPDX-License-Identifier: MIT
// 08: extending taxel with your own fusion policy and your own spatial index (docs/concepts.md).
// `PressureWeighted` averages contacts weighted by their pressure; `LinearScan` is the simplest
// IncrementalIndex there is. Both plug into ContactCloud by template argument, and the program
// checks them against the built-in ones: with equal pressures PressureWeighted equals Average,
// and LinearScan gives the same cloud as VoxelHash.
//   ./08_custom_policy
#include <cstdio>
#include <optional>
#include <taxel/taxel.hpp>
#include <vector>

namespace {

using taxel::Contact;
using taxel::Mat3;
using taxel::Vec3;

// A fusion policy: Scalar, Config, State, kMerges, init, fuse, mean, covariance
// (taxel::fusion::FusionPolicy).
template <taxel::Scalar S>
struct PressureWeighted {
  using Scalar = S;
  struct Config {
    S min_pressure = S(1e-6);  ///< pressures below this count as this (no zero weights)
  };
  struct State {
    Vec3<S> mean;
    Mat3<S> covariance;
    S weight;  ///< sum of the pressures fused so far
  };
  static constexpr bool kMerges = true;

  PressureWeighted() = default;
  explicit PressureWeighted(const Config& c) : config_(c) {}

  State init(const Contact<S>& c) const { return {c.position, c.covariance, w(c)}; }
  // Absorbs `c` into a point observed `n` times before; false would refuse it (a gate).
  bool fuse(State& s, const Contact<S>& c, std::uint32_t /*n*/) const {
    const S a = w(c) / (s.weight + w(c));  // this contact's share of the new mean
    s.mean += a * (c.position - s.mean);
    s.covariance = (S(1) - a) * (S(1) - a) * s.covariance + a * a * c.covariance;
    s.weight += w(c);
    return true;
  }
  const Vec3<S>& mean(const State& s) const { return s.mean; }
  const Mat3<S>& covariance(const State& s) const { return s.covariance; }

 private:
  S w(const Contact<S>& c) const { return std::max(c.pressure, config_.min_pressure); }
  Config config_{};
};
static_assert(taxel::fusion::FusionPolicy<PressureWeighted<double>>);

// An index: exact answers ordered by taxel::index::closer (distance, then id), plus the
// incremental operations ContactCloud uses (taxel::index::IncrementalIndex).
template <taxel::Scalar S>
class LinearScan {
 public:
  using Scalar = S;
  using Neighbor = taxel::index::Neighbor<S>;
  using PointId = taxel::index::PointId;

  std::optional<Neighbor> nearest_within(const Vec3<S>& q, S r) const {
    std::optional<Neighbor> best;
    for (const auto& [id, p] : points_) {
      const Neighbor n{id, taxel::index::squared_distance(p, q)};
      if (n.squared_distance <= r * r && (!best || taxel::index::closer(n, *best))) best = n;
    }
    return best;
  }
  std::vector<Neighbor> within(const Vec3<S>& q, S r) const {
    std::vector<Neighbor> out;
    for (const auto& [id, p] : points_) {
      const S d2 = taxel::index::squared_distance(p, q);
      if (d2 <= r * r) out.push_back({id, d2});
    }
    std::sort(out.begin(), out.end(), taxel::index::closer<S>);
    return out;
  }
  std::vector<Neighbor> knn(const Vec3<S>& q, std::size_t k) const {
    std::vector<Neighbor> out = within(q, std::numeric_limits<S>::infinity());
    out.resize(std::min(k, out.size()));
    return out;
  }
  std::size_t size() const { return points_.size(); }
  std::size_t memory_bytes() const { return points_.capacity() * sizeof(points_[0]); }
  void insert(PointId id, const Vec3<S>& p) { points_.push_back({id, p}); }
  void move(PointId id, const Vec3<S>& p) { find(id)->second = p; }
  void erase(PointId id) { points_.erase(find(id)); }
  void clear() { points_.clear(); }
  void reserve(std::size_t n) { points_.reserve(n); }
  bool contains(PointId id) const {
    return std::any_of(points_.begin(), points_.end(),
                       [&](const auto& e) { return e.first == id; });
  }

 private:
  auto find(PointId id) {
    return std::find_if(points_.begin(), points_.end(),
                        [&](const auto& e) { return e.first == id; });
  }
  std::vector<std::pair<PointId, Vec3<S>>> points_;
};
static_assert(taxel::index::IncrementalIndex<LinearScan<double>>);

}  // namespace

int main() {
  namespace tf = taxel::fusion;
  namespace ti = taxel::index;
  const auto contacts =
      taxel::sim::sliding_exploration(taxel::sim::Sphere(0.04), 50000, {.speed = 0.1});

  // Your policy and your index, by template argument.
  tf::ContactCloud<PressureWeighted<double>, LinearScan<double>> mine({.association_radius = 4e-3});
  tf::ContactCloud<tf::Average<double>, ti::VoxelHash<double>> builtin(
      {.association_radius = 4e-3});
  (void)mine.insert(std::span<const Contact<double>>(contacts));
  (void)builtin.insert(std::span<const Contact<double>>(contacts));

  // The simulator gives every contact the same pressure: the weighted mean is the plain mean.
  double worst = 0.0;
  const bool same_size = mine.size() == builtin.size();
  for (taxel::index::PointId i = 0; same_size && i < mine.size(); ++i)
    worst = std::max(worst, (mine.mean(i) - builtin.mean(i)).norm());
  std::printf("PressureWeighted + LinearScan: %zu points; Average + VoxelHash: %zu points\n",
              mine.size(), builtin.size());
  std::printf("largest difference between the clouds: %.3g m\n", worst);
  const bool ok = same_size && worst < 1e-12;
  std::printf("%s\n", ok ? "equal, as they must be" : "DIFFERENT");
  return ok ? 0 : 1;
}
