// SPDX-License-Identifier: MIT
// 10: does choosing where to touch pay? For six shapes and three seeds, a simulated pad pokes
// each object 40 times along random approach rays, and again along the rays the active policy
// picks (the largest expected drop of the surface's variance, taxel::shape). The table gives the
// random policy's surface error after 40 touches and the touch at which the active policy first
// reaches it (the GPAtlasRRT comparison of Rosales et al., IJHR 2018). Then recognition: each
// of ten models of different shapes, at random poses, explored for 10 touches with either
// policy; the share of trials whose most probable model is the right one after each touch.
//   ./10_active_touch_study [--quick] [--out DIR] [--threads N]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <taxel/core/parallel.hpp>
#include <taxel/io/ply.hpp>
#include <taxel/registration.hpp>
#include <taxel/shape.hpp>
#include <taxel/sim.hpp>
#include <variant>
#include <vector>

#include "cli.hpp"
#include "explore_harness.hpp"

namespace {

namespace ts = taxel::sim;
namespace tsh = taxel::shape;
using taxel::Vec3d;
using taxel_cli::appendf;

using AnyShape =
    std::variant<ts::Sphere, ts::Cylinder, ts::Box, ts::Cone, ts::Ellipsoid, ts::Torus>;

struct Named {
  std::string name;
  AnyShape shape;
};

// The six shapes of the surface study (their taxel-explore defaults).
std::vector<Named> surface_shapes() {
  return {{"sphere", ts::Sphere(0.03)},
          {"cylinder", ts::Cylinder(0.025, 0.04)},
          {"box", ts::Box(Vec3d(0.04, 0.03, 0.02))},
          {"cone", ts::Cone(0.03, 0.06)},
          {"ellipsoid", ts::Ellipsoid(Vec3d(0.045, 0.035, 0.025))},
          {"torus", ts::Torus(0.035, 0.012)}};
}

// Ten models of different shapes and sizes for recognition.
std::vector<Named> library_shapes() {
  return {{"ball_25", ts::Sphere(0.025)},
          {"ball_35", ts::Sphere(0.035)},
          {"can", ts::Cylinder(0.03, 0.045)},
          {"rod", ts::Cylinder(0.015, 0.05)},
          {"brick", ts::Box(Vec3d(0.045, 0.025, 0.015))},
          {"cube", ts::Box(Vec3d(0.03, 0.03, 0.03))},
          {"cone", ts::Cone(0.03, 0.06)},
          {"egg", ts::Ellipsoid(Vec3d(0.045, 0.03, 0.03))},
          {"lentil", ts::Ellipsoid(Vec3d(0.04, 0.04, 0.018))},
          {"ring", ts::Torus(0.035, 0.012)}};
}

// The first touch whose error is at most `target`, or 0 when none is.
int reached(const std::vector<taxel_explore::TouchRecord>& run, double target) {
  for (const auto& r : run) {
    if (r.surface_rms <= target) return r.touch;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  unsigned threads = 0;
  const taxel_cli::StudyOptions opt = taxel_cli::parse_study_options(
      "10_active_touch_study", "usage: 10_active_touch_study [--quick] [--out DIR] [--threads N]\n",
      "", argc, argv, [&](std::string_view a, taxel_cli::Args& args) {
        if (a != "--threads") return false;
        threads = args.number<unsigned>(0, 4096);
        return true;
      });
  const int touches = opt.quick ? 6 : 40;
  const std::vector<std::uint64_t> seeds =
      opt.quick ? std::vector<std::uint64_t>{1} : std::vector<std::uint64_t>{1, 2, 3};
  std::vector<Named> shapes = surface_shapes();
  if (opt.quick) shapes.resize(2);

  // Surface: random and active, every shape and seed.
  struct Job {
    std::size_t shape;
    std::uint64_t seed;
    taxel_explore::Policy policy;
  };
  std::vector<Job> jobs;
  for (std::size_t s = 0; s < shapes.size(); ++s) {
    for (const auto seed : seeds) {
      jobs.push_back({s, seed, taxel_explore::Policy::random});
      jobs.push_back({s, seed, taxel_explore::Policy::active});
    }
  }
  std::vector<std::vector<taxel_explore::TouchRecord>> runs(jobs.size());
  taxel::parallel_for(jobs.size(), threads, [&](std::size_t j) {
    taxel_explore::Settings st;
    st.policy = jobs[j].policy;
    st.touches = touches;
    st.seed = jobs[j].seed;
    runs[j] = std::visit(
        [&](const auto& sh) {
          return taxel_explore::explore(taxel_explore::AnyShape::of(sh), st,
                                        [](taxel_explore::TouchRecord& r) { r.estimate = {}; });
        },
        shapes[jobs[j].shape].shape);
  });
  std::string text;
  appendf(text, "Surface error (symmetric RMS, mm) after %d touches, and the touch at which the\n",
          touches);
  appendf(text, "active policy first reaches the random policy's final error:\n\n");
  appendf(text, "%-10s %4s %10s %10s %10s %10s %10s %9s %9s\n", "shape", "seed", "random_mm",
          "rand_sgn", "active_mm", "act_sgn", "reached_at", "rand_cov", "act_cov");
  std::vector<int> at;
  int never = 0;
  for (std::size_t j = 0; j < jobs.size(); j += 2) {
    const auto& rnd = runs[j];
    const auto& act = runs[j + 1];
    const double target = rnd.back().surface_rms;
    const int k = reached(act, target);
    if (k == 0) ++never;
    at.push_back(k == 0 ? touches + 1 : k);
    appendf(text, "%-10s %4llu %10.3f %+10.3f %10.3f %+10.3f %10s %9.3f %9.3f\n",
            shapes[jobs[j].shape].name.c_str(), static_cast<unsigned long long>(jobs[j].seed),
            1e3 * target, 1e3 * rnd.back().surface_signed, 1e3 * act.back().surface_rms,
            1e3 * act.back().surface_signed, k == 0 ? "never" : std::to_string(k).c_str(),
            rnd.back().coverage, act.back().coverage);
  }
  std::vector<int> sorted = at;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.size() % 2
                            ? sorted[sorted.size() / 2]
                            : 0.5 * (sorted[sorted.size() / 2 - 1] + sorted[sorted.size() / 2]);
  appendf(text,
          "\nmedian touch to reach: %.1f of %d; runs where active never reached it: %d of %zu\n",
          median, touches, never, at.size());
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);

  // Recognition: every library model as the object, at random poses (seeds), both policies.
  const std::vector<Named> models = library_shapes();
  taxel::registration::ObjectLibrary<double> library({.threads = 1});
  for (const auto& m : models) {
    std::visit(
        [&](const auto& sh) { library.add(m.name, ts::sample_surface_spacing(sh, 1.5e-3, 5)); },
        m.shape);
  }
  const int rtouches = opt.quick ? 3 : 10;
  const int trials = opt.quick ? 1 : 3;
  std::vector<Job> rjobs;
  for (std::size_t s = 0; s < (opt.quick ? 2 : models.size()); ++s) {
    for (int t = 0; t < trials; ++t) {
      rjobs.push_back({s, 100 + std::uint64_t(t), taxel_explore::Policy::random});
      rjobs.push_back({s, 100 + std::uint64_t(t), taxel_explore::Policy::active});
    }
  }
  std::vector<std::vector<taxel_explore::TouchRecord>> rruns(rjobs.size());
  taxel::parallel_for(rjobs.size(), threads, [&](std::size_t j) {
    taxel_explore::Settings st;
    st.policy = rjobs[j].policy;
    st.touches = rtouches;
    st.seed = rjobs[j].seed;
    st.library = &library;
    rruns[j] = std::visit(
        [&](const auto& sh) {
          return taxel_explore::explore(taxel_explore::AnyShape::of(sh), st,
                                        [](taxel_explore::TouchRecord& r) { r.estimate = {}; });
        },
        models[rjobs[j].shape].shape);
  });
  std::string rec;
  appendf(rec,
          "\nRecognition among %zu models: share of trials whose most probable model is right\n",
          models.size());
  appendf(rec, "%-6s %8s %8s\n", "touch", "random", "active");
  for (int k = 0; k < rtouches; ++k) {
    int right[2] = {0, 0}, total[2] = {0, 0};
    for (std::size_t j = 0; j < rjobs.size(); ++j) {
      const int p = rjobs[j].policy == taxel_explore::Policy::active;
      ++total[p];
      right[p] += rruns[j][std::size_t(k)].top1 == models[rjobs[j].shape].name;
    }
    appendf(rec, "%-6d %8.3f %8.3f\n", k + 1, double(right[0]) / total[0],
            double(right[1]) / total[1]);
  }
  std::fputs(rec.c_str(), stdout);
  if (!opt.out.empty()) {
    std::filesystem::create_directories(opt.out);
    taxel_cli::write_output((std::filesystem::path(opt.out) / "active_touch.txt").string(),
                            text + rec);
  }
  return 0;
}
