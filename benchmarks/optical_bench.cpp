// SPDX-License-Identifier: MIT
// Camera-based tactile frames (optical/): one 240 x 320 frame (a GelSight Mini's) to gradients,
// mask and heights, with and without marker handling, and the Poisson integration alone.
#include <benchmark/benchmark.h>

#include <random>
#include <taxel/optical.hpp>
#include <taxel/sim/optical.hpp>
#include <vector>

namespace {

namespace to = taxel::optical;

struct Setup {
  static constexpr int kRows = 240, kCols = 320;
  to::Calibration cal;
  std::vector<to::RgbFrame> frames;
  Setup() {
    const double pixel = 0.0634e-3, ball = 2e-3;
    to::ShadingModel model;
    const to::Colour bg = to::render_background(model, kRows, kCols);
    std::mt19937_64 rng(1);
    const to::Plane zero = to::Plane::Zero(kRows, kCols);
    const to::RgbFrame empty = to::render(zero, zero, bg, model, 2.0, rng);
    for (int i = 0; i < 6; ++i) {
      const auto g = taxel::sim::press_ball(kRows, kCols, pixel, ball, 0.5e-3, 60 + 40 * i, 120);
      frames.push_back(to::render(g.gx, g.gy, bg, model, 2.0, rng));
    }
    cal = to::calibrate(frames, empty, {.ball_radius = ball, .pixel = pixel});
  }
};

const Setup& setup() {
  static const Setup s;
  return s;
}

void Reconstruct(benchmark::State& state) {
  to::Calibration cal = setup().cal;
  cal.markers = state.range(0) != 0;
  to::PoissonSolver solver(Setup::kRows, Setup::kCols);
  std::size_t i = 0;
  for (auto _ : state) {
    const to::HeightMap map =
        to::reconstruct(setup().frames[i++ % setup().frames.size()], cal, solver);
    benchmark::DoNotOptimize(map.height.data());
  }
  state.counters["frames_per_second"] =
      benchmark::Counter(double(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(Reconstruct)->Arg(0)->Arg(1)->ArgName("markers")->Unit(benchmark::kMillisecond);

void Poisson(benchmark::State& state) {
  to::PoissonSolver solver(Setup::kRows, Setup::kCols);
  const to::Plane gx = to::Plane::Random(Setup::kRows, Setup::kCols) * 0.1;
  const to::Plane gy = to::Plane::Random(Setup::kRows, Setup::kCols) * 0.1;
  const auto border = state.range(0) != 0 ? to::PoissonBorder::zero : to::PoissonBorder::free;
  for (auto _ : state) {
    const to::Plane h = solver.integrate(gx, gy, 0.0634e-3, border);
    benchmark::DoNotOptimize(h.data());
  }
}
BENCHMARK(Poisson)->Arg(0)->Arg(1)->ArgName("zero_border")->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
