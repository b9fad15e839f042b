// SPDX-License-Identifier: MIT
// ICP and recognition (the targets and peer figures are in docs/performance.md):
//  - a 2000-point partial tactile cloud (5 patches of 15 mm radius, sigma 1 mm) against a
//    10000-point 80 x 60 x 40 mm box model, starts within 10 deg / 5 mm, 30 seeded trials
//    cycled; point-to-plane (target <= 3 ms per alignment at <= 0.25 mm RMS pose error) and
//    point-to-point; exact correspondences, and the closest-point field for the first
//    iterations then exact;
//  - 500 vs 2000 and 5000 vs 50000 points;
//  - recognition of one cloud among 10 models with 28 starts each (target <= 150 ms).
// Counters: iterations, RMS pose error (mm; RMS over the cloud of |T_est p - T_true p|) and
// success (error below 1 mm), averaged over the trials run.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <taxel/registration.hpp>
#include <taxel/sim/sampling.hpp>
#include <taxel/sim/shapes.hpp>
#include <type_traits>
#include <vector>

namespace {

using namespace taxel;
using namespace taxel::registration;

struct Trial {
  std::vector<Vec3d> source;  // in the sensor frame
  Isometry3d truth;           // T_model_source
  Isometry3d start;
};

// Partial clouds of the box, posed by a random truth, with starts within 10 deg / 5 mm of it.
std::vector<Trial> make_trials(std::size_t points, int count, std::uint64_t seed) {
  const sim::Box box(Vec3d(0.04, 0.03, 0.02));
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Trial> trials;
  for (int k = 0; k < count; ++k) {
    sim::PatchConfig pc;
    pc.points = points;
    const PointCloud<double> cloud =
        sim::tactile_patches(box, pc, seed * 1000 + static_cast<std::uint64_t>(k));
    Trial t;
    t.truth = Isometry3d::Identity();
    t.truth.linear() =
        Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng)).normalized())
            .toRotationMatrix();
    t.truth.translation() = 0.1 * Vec3d(g(rng), g(rng), g(rng));
    for (const auto& p : cloud.points) t.source.push_back(t.truth.inverse() * p);
    const Vec3d axis = Vec3d(g(rng), g(rng), g(rng)).normalized();
    const Vec3d dir = Vec3d(g(rng), g(rng), g(rng)).normalized();
    Isometry3d offset = Isometry3d::Identity();
    offset.linear() = Eigen::AngleAxisd(u(rng) * 10.0 * M_PI / 180.0, axis).toRotationMatrix();
    offset.translation() = u(rng) * 0.005 * dir;
    t.start = offset * t.truth;
    trials.push_back(std::move(t));
  }
  return trials;
}

double pose_error(const Trial& t, const Isometry3d& est) {
  double sum = 0.0;
  for (const auto& p : t.source) sum += (est * p - t.truth * p).squaredNorm();
  return std::sqrt(sum / static_cast<double>(t.source.size()));
}

// Point-to-plane also stops when the RMSE changes by less than 0.1 % (it converges in a few
// Gauss-Newton steps, and more do not lower the pose error); point-to-point converges slowly,
// so that rule would stop it early: it runs to the update tolerances.
template <class Error>
IcpConfig bench_config() {
  IcpConfig cfg;
  cfg.max_iterations = 50;
  cfg.max_distance = 0.01;
  cfg.translation_tolerance = 1e-5;
  cfg.rotation_tolerance = 1e-4;
  if (std::is_same_v<Error, PointToPlane>) cfg.relative_error_tolerance = 1e-3;
  return cfg;
}

// field_first: a whole alignment on the closest-point field, then an exact one from there.
// coarse: IcpConfig::coarse_points = 500 (a subsample on the field first, then all points).
template <class Error>
void run_icp(benchmark::State& state, std::size_t model_points, std::size_t cloud_points,
             bool field_first, bool coarse = false) {
  const Target<double> target(
      sim::sample_surface(sim::Box(Vec3d(0.04, 0.03, 0.02)), model_points, 1),
      TargetConfig{.field_cell = field_first ? 2e-3 : 0.0});
  const std::vector<Trial> trials = make_trials(cloud_points, 30, 7);
  IcpConfig approx_cfg = bench_config<Error>();
  approx_cfg.approximate = true;
  Icp<Error> approx(approx_cfg);
  IcpConfig exact_cfg = bench_config<Error>();
  if (coarse) exact_cfg.coarse_points = 500;
  Icp<Error> exact(exact_cfg);
  std::size_t k = 0;
  double iterations = 0.0, error = 0.0, success = 0.0, runs = 0.0;
  for (auto _ : state) {
    const Trial& t = trials[k++ % trials.size()];
    Isometry3d start = t.start;
    int its = 0;
    if (field_first) {
      const IcpResult r = approx.align(target, std::span<const Vec3d>(t.source), start);
      start = r.transform;
      its += r.iterations;
    }
    const IcpResult r = exact.align(target, std::span<const Vec3d>(t.source), start);
    benchmark::DoNotOptimize(r.transform);
    its += r.iterations;
    const double e = pose_error(t, r.transform);
    iterations += its;
    error += e;
    success += e < 1e-3 ? 1.0 : 0.0;
    runs += 1.0;
  }
  state.counters["iterations"] = iterations / runs;
  state.counters["pose_err_mm"] = 1e3 * error / runs;
  state.counters["success"] = success / runs;
}

void BM_PointToPlane_2k_vs_10k(benchmark::State& s) {
  run_icp<PointToPlane>(s, 10000, 2000, false);
}
void BM_PointToPlane_2k_vs_10k_field(benchmark::State& s) {
  run_icp<PointToPlane>(s, 10000, 2000, true);
}
void BM_PointToPlane_2k_vs_10k_coarse(benchmark::State& s) {
  run_icp<PointToPlane>(s, 10000, 2000, false, true);
}
void BM_PointToPoint_2k_vs_10k_coarse(benchmark::State& s) {
  run_icp<PointToPoint>(s, 10000, 2000, false, true);
}
void BM_PointToPlane_5k_vs_50k_coarse(benchmark::State& s) {
  run_icp<PointToPlane>(s, 50000, 5000, false, true);
}
void BM_PointToPoint_2k_vs_10k(benchmark::State& s) {
  run_icp<PointToPoint>(s, 10000, 2000, false);
}
void BM_PointToPoint_2k_vs_10k_field(benchmark::State& s) {
  run_icp<PointToPoint>(s, 10000, 2000, true);
}
void BM_PointToPlane_500_vs_2k(benchmark::State& s) { run_icp<PointToPlane>(s, 2000, 500, false); }
void BM_PointToPlane_5k_vs_50k(benchmark::State& s) {
  run_icp<PointToPlane>(s, 50000, 5000, false);
}
void BM_PointToPlane_5k_vs_50k_field(benchmark::State& s) {
  run_icp<PointToPlane>(s, 50000, 5000, true);
}
// Per iteration, without any stopping rule: exact point-to-plane iterations (tolerances 0)
// from the same starts, as many as the argument. With 10, the time per iteration is a tenth
// of the figure and includes the first, farthest search and the final correspondence pass;
// the difference between 10 and 1 over 9 is the cost of one more iteration.
void BM_PointToPlane_2k_vs_10k_iterations(benchmark::State& state) {
  const Target<double> target(sim::sample_surface(sim::Box(Vec3d(0.04, 0.03, 0.02)), 10000, 1));
  const std::vector<Trial> trials = make_trials(2000, 30, 7);
  IcpConfig cfg;
  cfg.max_iterations = static_cast<int>(state.range(0));
  cfg.max_distance = 0.01;
  cfg.translation_tolerance = 0.0;
  cfg.rotation_tolerance = 0.0;
  cfg.keep_stable_matches = state.range(1) != 0;
  Icp<PointToPlane> icp(cfg);
  std::size_t k = 0;
  double error = 0.0, runs = 0.0;
  for (auto _ : state) {
    const Trial& t = trials[k++ % trials.size()];
    const IcpResult r = icp.align(target, std::span<const Vec3d>(t.source), t.start);
    benchmark::DoNotOptimize(r.transform);
    error += pose_error(t, r.transform);
    runs += 1.0;
  }
  state.counters["pose_err_mm"] = 1e3 * error / runs;
}
BENCHMARK(BM_PointToPlane_2k_vs_10k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_2k_vs_10k_iterations)
    ->ArgNames({"iterations", "keep_stable"})
    ->ArgsProduct({{1, 10}, {1, 0}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_2k_vs_10k_field)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_2k_vs_10k_coarse)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPoint_2k_vs_10k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPoint_2k_vs_10k_coarse)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPoint_2k_vs_10k_field)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_500_vs_2k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_5k_vs_50k)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_5k_vs_50k_field)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPlane_5k_vs_50k_coarse)->Unit(benchmark::kMillisecond);

// Target preparation (grid, kd-tree, PCA normals, closest-point field): paid once per model.
void BM_TargetBuild_10k(benchmark::State& state) {
  const PointCloud<double> model = sim::sample_surface(sim::Box(Vec3d(0.04, 0.03, 0.02)), 10000, 1);
  PointCloud<double> bare = model;
  bare.normals.clear();
  for (auto _ : state) {
    const Target<double> t(bare, TargetConfig{.field_cell = 2e-3});
    benchmark::DoNotOptimize(t.size());
  }
}
BENCHMARK(BM_TargetBuild_10k)->Unit(benchmark::kMillisecond);

// One partial cloud among 10 models (spheres, cylinders, boxes of several sizes), 28 starts
// each (4 principal-axes + 24 cube rotations), on 1 thread and on 2 (the argument); wall time.
void BM_Recognize_10_models(benchmark::State& state) {
  LibraryConfig cfg;
  cfg.threads = static_cast<unsigned>(state.range(0));
  ObjectLibrary<double> lib(cfg);
  std::vector<std::function<PointCloud<double>(std::uint64_t)>> touch;
  const auto add = [&](const char* name, auto shape) {
    lib.add(name, sim::sample_surface(shape, 10000, 1));
    touch.push_back([shape](std::uint64_t seed) {
      return sim::tactile_patches(shape, sim::PatchConfig{}, seed);
    });
  };
  add("sphere 40", sim::Sphere(0.04));
  add("sphere 25", sim::Sphere(0.025));
  add("sphere 60", sim::Sphere(0.06));
  add("cylinder 30 x 100", sim::Cylinder(0.03, 0.05));
  add("cylinder 20 x 60", sim::Cylinder(0.02, 0.03));
  add("cylinder 40 x 40", sim::Cylinder(0.04, 0.02));
  add("box 80 x 60 x 40", sim::Box(Vec3d(0.04, 0.03, 0.02)));
  add("cube 50", sim::Box(Vec3d(0.025, 0.025, 0.025)));
  add("bar 120 x 40 x 20", sim::Box(Vec3d(0.06, 0.02, 0.01)));
  add("plate 100 x 100 x 10", sim::Box(Vec3d(0.05, 0.05, 0.005)));
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<PointCloud<double>> clouds;
  std::vector<std::size_t> truth;
  for (int k = 0; k < 30; ++k) {
    const std::size_t o = static_cast<std::size_t>(k) % touch.size();
    Isometry3d T = Isometry3d::Identity();
    T.linear() = Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng)).normalized())
                     .toRotationMatrix();
    T.translation() = 0.1 * Vec3d(g(rng), g(rng), g(rng));
    clouds.push_back(transformed(touch[o](500 + static_cast<std::uint64_t>(k)), T));
    truth.push_back(o);
  }
  std::size_t k = 0;
  double right = 0.0, runs = 0.0;
  for (auto _ : state) {
    const std::size_t i = k++ % clouds.size();
    const ObjectRecognition r = lib.recognize(clouds[i]);
    benchmark::DoNotOptimize(r.margin);
    right += r.best == lib.name(truth[i]) ? 1.0 : 0.0;
    runs += 1.0;
  }
  state.counters["top1"] = right / runs;
}
BENCHMARK(BM_Recognize_10_models)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(30)
    ->Arg(1)
    ->Arg(2)
    ->UseRealTime();

}  // namespace

// Closest point on a 5 120-triangle icosphere (a mesh model, or taxel-simulate --shape mesh):
// through TriangleMesh's bounding-volume hierarchy, and by a scan of every triangle (each a
// one-triangle mesh), the method before the hierarchy. Queries within 5 mm of the surface, as a
// pressed pad's tactels are.
std::vector<taxel::Vec3d> mesh_queries(std::size_t n) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> r(0.035, 0.045);
  std::vector<taxel::Vec3d> q(n);
  for (auto& p : q) p = taxel::Vec3d(g(rng), g(rng), g(rng)).normalized() * r(rng);
  return q;
}

void BM_MeshClosest_hierarchy(benchmark::State& state) {
  const taxel::sim::TriangleMesh mesh = taxel::sim::icosphere(0.04, 4);
  const auto q = mesh_queries(1000);
  for (auto _ : state) {
    for (const auto& p : q) benchmark::DoNotOptimize(mesh.closest_point(p));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(q.size()));
}

void BM_MeshClosest_scan(benchmark::State& state) {
  const taxel::sim::TriangleMesh mesh = taxel::sim::icosphere(0.04, 4);
  std::vector<taxel::sim::TriangleMesh> single;
  for (const auto& t : mesh.triangles()) {
    single.emplace_back(std::vector<taxel::Vec3d>{mesh.vertices()[t[0]], mesh.vertices()[t[1]],
                                                  mesh.vertices()[t[2]]},
                        std::vector<taxel::sim::TriangleMesh::Triangle>{{0, 1, 2}});
  }
  const auto q = mesh_queries(20);
  for (auto _ : state) {
    for (const auto& p : q) {
      double best = std::numeric_limits<double>::infinity();
      for (const auto& m : single) best = std::min(best, (m.closest_point(p) - p).squaredNorm());
      benchmark::DoNotOptimize(best);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(q.size()));
}

BENCHMARK(BM_MeshClosest_hierarchy)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MeshClosest_scan)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
