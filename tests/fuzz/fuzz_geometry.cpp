// SPDX-License-Identifier: MIT
// Fuzzes the geometry built from clouds: UniformGrid, Target (with its closest-point field),
// Icp (both errors) and ObjectLibrary, on fuzzer-chosen clouds. The first byte picks how the
// rest becomes coordinates: raw doubles (any finite value, huge ones included), small integers
// on a millimetre lattice (duplicates and flat or collinear sets), or one axis only (collinear).
// ICP's and the object library's options come from the input's last bytes. Every call must
// return or throw std::invalid_argument; answers must match brute force, and every transform
// must be finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <taxel/index/brute_force.hpp>
#include <taxel/index/uniform_grid.hpp>
#include <taxel/registration.hpp>
#include <vector>

#include "byte_range.hpp"

namespace {

using taxel::Vec3d;

std::vector<Vec3d> decode(const std::uint8_t* data, std::size_t size) {
  std::vector<Vec3d> pts;
  if (size == 0) return pts;
  const int mode = data[0] % 3;
  ++data;
  --size;
  if (mode == 0) {  // raw doubles: 24 bytes a point, non-finite ones dropped
    for (std::size_t i = 0; i + 24 <= size && pts.size() < 96; i += 24) {
      double v[3];
      std::memcpy(v, data + i, sizeof v);
      if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) {
        pts.emplace_back(v[0], v[1], v[2]);
      }
    }
  } else if (mode == 1) {  // a 1 mm lattice of 16 steps per axis: duplicates, planes, lines
    for (std::size_t i = 0; i + 3 <= size && pts.size() < 96; i += 3) {
      pts.emplace_back(1e-3 * (data[i] % 16), 1e-3 * (data[i + 1] % 16), 1e-3 * (data[i + 2] % 16));
    }
  } else {  // one axis: collinear
    for (std::size_t i = 0; i < size && pts.size() < 96; ++i) {
      pts.emplace_back(1e-3 * data[i], 0.0, 0.0);
    }
  }
  return pts;
}

void check_against_brute(const taxel::registration::Target<double>& t,
                         const std::vector<Vec3d>& pts, const Vec3d& q) {
  taxel::index::BruteForce<double> brute;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    brute.insert(static_cast<taxel::index::PointId>(i), pts[i]);
  }
  for (const double r : {1e-3, 1.0, std::numeric_limits<double>::infinity()}) {
    const auto a = t.nearest_within(q, r);
    const auto b = brute.nearest_within(q, r);
    if (a.has_value() != b.has_value()) std::abort();
    if (a && a->squared_distance != b->squared_distance) std::abort();
    // From a hint, with the radius of the ball whose queries share the answer: never more
    // than half the gap between the nearest and the second-nearest point.
    const auto two = brute.knn(q, 2);
    for (const auto hint :
         {taxel::index::PointId{0}, static_cast<taxel::index::PointId>(pts.size() - 1),
          two.empty() ? taxel::index::PointId{0} : two.front().id}) {
      const auto st = t.nearest_stable(q, r, hint);
      if (st.has_value() != b.has_value()) std::abort();
      if (!st) continue;
      if (st->nearest.squared_distance != b->squared_distance) std::abort();
      if (!(st->radius >= 0.0)) std::abort();
      if (two.size() == 2 && st->radius > 0.5 * (std::sqrt(two[1].squared_distance) -
                                                 std::sqrt(two[0].squared_distance))) {
        std::abort();
      }
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace tr = taxel::registration;
  const std::vector<Vec3d> pts = decode(data, size);
  if (pts.empty()) return 0;
  try {
    const taxel::index::UniformGrid<double> grid(pts);
    const auto hit = grid.nearest_within(pts.front(), 0.0);
    if (!hit || hit->squared_distance != 0.0) std::abort();
  } catch (const std::invalid_argument&) {
    return 0;  // a cloud too wide to grid; Target would refuse it the same way
  }
  taxel::PointCloud<double> cloud;
  cloud.points = pts;
  try {
    const tr::Target<double> target(cloud,
                                    tr::TargetConfig{.field_cell = 1e-3, .field_max_cells = 512});
    check_against_brute(target, pts, pts.back() + Vec3d(1e-4, -2e-4, 3e-4));
    check_against_brute(target, pts, Vec3d(0, 0, 0));

    // ICP of the cloud onto itself from a small offset: whatever the status, finite numbers.
    // Its options come from the input's last five bytes, over the ranges IcpConfig accepts:
    // the distance gate 1e-9 - 1e3 m or none, trimming 0 - 0.99, tolerances 1e-15 - 1,
    // approximate correspondences and a coarse stage of up to 63 points.
    tr::IcpConfig config{.max_iterations = 10};
    if (size >= 6) {
      using taxel::fuzz::log_range;
      const std::uint8_t* tail = data + size - 5;
      config.max_distance =
          tail[0] == 255 ? std::numeric_limits<double>::infinity() : log_range(tail[0], 1e-9, 1e3);
      config.trim_fraction = 0.99 * (tail[1] / 255.0);
      config.translation_tolerance = log_range(tail[2], 1e-15, 1.0);
      config.rotation_tolerance = log_range(tail[3], 1e-15, 1.0);
      config.approximate = (tail[4] & 64) != 0;
      config.coarse_points = tail[4] & 63;
    }
    Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
    start.translation() = Vec3d(1e-3, 0, -1e-3);
    const std::span<const Vec3d> source(pts);
    const tr::IcpResult a = tr::Icp<tr::PointToPlane>(config).align(target, source, start);
    const tr::IcpResult b = tr::Icp<tr::PointToPoint>(config).align(target, source, start);
    for (const auto* r : {&a, &b}) {
      if (!r->transform.matrix().allFinite() || !std::isfinite(r->rmse)) std::abort();
    }
    // Keeping stable matches changes no correspondence, so no bit of the result.
    tr::IcpConfig searching = config;
    searching.keep_stable_matches = false;
    const tr::IcpResult c = tr::Icp<tr::PointToPlane>(searching).align(target, source, start);
    if (!(c.transform.matrix() == a.transform.matrix()) || !(c.rmse == a.rmse) ||
        c.iterations != a.iterations) {
      std::abort();
    }

    // The library's options from the four bytes before ICP's, over the ranges LibraryConfig
    // accepts (iteration and start counts kept small for the fuzzer's speed), with ICP's
    // options above as its refinement.
    tr::LibraryConfig lc;
    lc.rotation_starts = 2;
    if (size >= 10) {
      using taxel::fuzz::log_range;
      const std::uint8_t* head = data + size - 9;
      lc.refine = config;
      lc.coarse_iterations = 1 + head[0] % 12;
      lc.coarse_points = 6 + (std::size_t{1} << (head[0] / 12 % 11)) - 1;
      lc.refine_points = 6 + (std::size_t{1} << (head[1] % 11)) - 1;
      lc.coarse_trim = 0.99 * ((head[1] >> 4) / 15.0);
      lc.pca_starts = (head[2] & 1) != 0;
      lc.rotation_starts = lc.pca_starts ? (head[2] >> 1) % 25 : 1 + (head[2] >> 1) % 24;
      lc.refine_best = 1 + (head[2] >> 6);
      lc.exact_models = 1 + (head[3] & 3);
      lc.hopeless_factor = (head[3] & 4) != 0 ? std::numeric_limits<double>::infinity()
                                              : log_range(head[3], 1.0 + 1e-12, 1e6);
      lc.field_cell = (head[3] & 8) != 0 ? 0.0 : log_range(head[0], 1e-6, 1.0);
      lc.score_gate = log_range(head[1], 1e-9, 1e3);
      lc.unknown_score = log_range(head[2], 1e-9, 1e3);
      lc.threads = 1 + (head[3] >> 7);
    }
    tr::ObjectLibrary<double> library(lc);
    library.add("model", cloud, {.field_max_cells = 512});
    const tr::ObjectRecognition rec = library.recognize(cloud);
    for (const auto& m : rec.ranking) {
      if (!m.transform.matrix().allFinite() || std::isnan(m.score)) std::abort();
    }
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
