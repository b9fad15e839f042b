// SPDX-License-Identifier: MIT
// Shape with uncertainty (shape/): adding a point to an implicit surface whose experts hold 64
// points each (a local rank update) against refitting an exact process over the same
// observations; fusing one contact through Explorer; scoring 1000 candidate touches; and
// querying 10 000 points for the mean and gradient, and for the mean and variance.
#include <benchmark/benchmark.h>

#include <random>
#include <taxel/shape.hpp>
#include <vector>

namespace {

namespace sh = taxel::shape;
using taxel::Vec3d;

// A sphere of radius 30 mm densely touched: points on a Fibonacci sphere, as many as gives
// `per_expert` points to an expert of side 15 mm (it holds the points of a 30 mm cube).
sh::ImplicitSurface<> touched_sphere(std::size_t per_expert) {
  const double r = 0.03, L = 0.015;
  // A cube of side 2 L centred on the sphere holds about (2 L)^2 of its surface.
  const auto n = static_cast<int>(double(per_expert) * 4 * 3.14159 * r * r / (4 * L * L));
  sh::ImplicitSurface<> s({.expert_size = L, .prior_radius = 0.025});
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double phi = i * 3.14159265358979 * (3.0 - std::sqrt(5.0));
    const Vec3d u(std::sqrt(1 - z * z) * std::cos(phi), std::sqrt(1 - z * z) * std::sin(phi), z);
    (void)s.insert(r * u, u, 1e-8);
  }
  return s;
}

void AddPoint(benchmark::State& state) {
  sh::ImplicitSurface<> s = touched_sphere(static_cast<std::size_t>(state.range(0)));
  const Vec3d u = Vec3d(0.3, -0.5, 0.8).normalized();
  for (auto _ : state) {
    const auto id = s.insert(0.0301 * u, u, 1e-8);
    state.PauseTiming();
    s.erase(*id);
    state.ResumeTiming();
  }
  state.counters["largest_expert_points"] = double(s.largest_expert()) / 3.0;
}
BENCHMARK(AddPoint)->Arg(64)->Unit(benchmark::kMicrosecond);

// The alternative to a rank update: refit one exact process over one expert's observations.
void RefitExpert(benchmark::State& state) {
  const sh::ImplicitSurface<> s = touched_sphere(static_cast<std::size_t>(state.range(0)));
  const auto* e = s.find(s.nearest_expert(Vec3d(0.0, 0.0, 0.03)));
  for (auto _ : state) {
    sh::GaussianProcess<> gp(s.kernel());
    for (Eigen::Index i = 0; i < e->process.positions().cols(); ++i)
      (void)gp.add(e->process.positions().col(i), e->process.values()(i), e->process.noise()(i));
    benchmark::DoNotOptimize(gp.weights().data());
  }
  state.counters["observations"] = double(e->process.size());
}
BENCHMARK(RefitExpert)->Arg(64)->Unit(benchmark::kMicrosecond);

// One contact through the whole path: fused into the cloud (a point moves) and the surface
// updated (the point's observations leave and rejoin its 8 experts).
void ExplorerContact(benchmark::State& state) {
  sh::Explorer<> ex(
      {.workspace_min = Vec3d::Constant(-0.04), .workspace_max = Vec3d::Constant(0.04)});
  std::vector<taxel::Contact<double>> seed;
  for (int i = -6; i <= 6; ++i) {
    for (int j = -6; j <= 6; ++j) {
      taxel::Contact<double> c;
      c.position = Vec3d(2e-3 * i, 2e-3 * j, 0.03);
      c.normal = Vec3d::UnitZ();
      c.covariance = taxel::Mat3d(Eigen::Vector3d(1e-6, 1e-6, 1e-8).asDiagonal());
      seed.push_back(c);
    }
  }
  ex.add_contacts(seed);
  taxel::Contact<double> c = seed[seed.size() / 2];
  c.position.z() += 1e-4;
  for (auto _ : state) ex.add_contacts(std::span(&c, 1));
}
BENCHMARK(ExplorerContact)->Unit(benchmark::kMicrosecond);

struct Scene {
  sh::ImplicitSurface<> surface = touched_sphere(64);
  sh::Grid grid = sh::Grid::covering(Vec3d::Constant(-0.045), Vec3d::Constant(0.045), 0.003);
  std::vector<double> field = surface.sample(grid);
  sh::SurfaceMesh mesh = sh::extract_surface(surface, grid, field);
  std::vector<sh::TouchCandidate> rays;
  Eigen::Matrix3Xd queries;
  Scene() {
    std::mt19937_64 rng(1);
    rays = sh::approach_rays(Vec3d::Zero(), 0.07, 0.02, 1000, rng);
    std::normal_distribution<double> g;
    queries.resize(3, 10000);
    for (int i = 0; i < 10000; ++i) {
      const Vec3d u = Vec3d(g(rng), g(rng), g(rng)).normalized();
      queries.col(i) = (0.03 + 0.003 * g(rng)) * u;
    }
  }
};
const Scene& scene() {
  static const Scene s;
  return s;
}

void ScoreTouches(benchmark::State& state) {
  const Scene& s = scene();
  for (auto _ : state) {
    const auto scores = sh::score_touches(s.surface, s.grid, s.field, s.mesh.mesh.vertices, s.rays);
    benchmark::DoNotOptimize(scores.data());
  }
  state.counters["candidates"] = double(s.rays.size());
}
BENCHMARK(ScoreTouches)->Unit(benchmark::kMillisecond);

void QueryMeanGradient(benchmark::State& state) {
  const Scene& s = scene();
  for (auto _ : state) {
    double sum = 0.0;
    for (Eigen::Index i = 0; i < s.queries.cols(); ++i) {
      Vec3d g = Vec3d::Zero();
      sum += s.surface.mean(s.queries.col(i), g) + g.x();
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["points"] = double(s.queries.cols());
}
BENCHMARK(QueryMeanGradient)->Unit(benchmark::kMillisecond);

void QueryMeanVariance(benchmark::State& state) {
  const Scene& s = scene();
  std::vector<double> mean(static_cast<std::size_t>(s.queries.cols())), var(mean.size());
  for (auto _ : state) {
    s.surface.evaluate(s.queries, mean.data(), var.data());
    benchmark::DoNotOptimize(var.data());
  }
  state.counters["points"] = double(s.queries.cols());
}
BENCHMARK(QueryMeanVariance)->Unit(benchmark::kMillisecond);

void QueryMean(benchmark::State& state) {
  const Scene& s = scene();
  std::vector<double> mean(static_cast<std::size_t>(s.queries.cols()));
  for (auto _ : state) {
    s.surface.evaluate(s.queries, mean.data(), nullptr);
    benchmark::DoNotOptimize(mean.data());
  }
  state.counters["points"] = double(s.queries.cols());
}
BENCHMARK(QueryMean)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
