// SPDX-License-Identifier: MIT
// Contact fusion end to end (nearest within radius + policy update + index move, or insert)
// for every policy x index, on 200k-contact sliding explorations of a sphere, a cylinder and a
// box; frames of the pad model inserted one contact at a time and a frame at a time; plus
// query-only replay, a 100k-point growth case, and readings to contacts per active tactel.
// Peers in the same binary: DynamicKdTree (taxel's exact wrapper of nanoflann 1.4's
// KDTreeSingleIndexDynamicAdaptor, a logarithmic forest of static kd-trees, as Debian 12 ships
// it; not a newer nanoflann), brute force, and a reference hash grid on tsl::robin_map
// (reference_grid.hpp, when robin-map-dev is installed).
//   ./fusion_bench --benchmark_filter='Fuse<tf::Kalman<double>, ti::VoxelHash'
//       --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <map>
#include <random>
#include <span>
#include <string>
#include <taxel/fusion.hpp>
#include <taxel/index.hpp>
#include <taxel/sim.hpp>
#include <vector>

#ifdef TAXEL_BENCH_HAVE_ROBIN_MAP
#include "reference_grid.hpp"
#endif

namespace tf = taxel::fusion;
namespace ti = taxel::index;

namespace {

constexpr std::size_t kStream = 200000;
constexpr double kRadius = 2e-3;
// These streams carry 1 mm of noise along the normal, which ContactCloud's default gate would
// widen to 6 mm (association_sigmas). The index comparisons and the reference grid run the
// fixed 2 mm gate, the same work for every index; FuseWidenedGate measures the default.
template <class Cloud>
typename Cloud::Config fixed_gate() {
  typename Cloud::Config c;
  c.association_radius = typename Cloud::Scalar(kRadius);
  c.association_sigmas = 0;
  return c;
}

enum class ShapeId { sphere, cylinder, box };

template <class S>
const std::vector<taxel::Contact<S>>& stream(ShapeId shape) {
  static std::map<ShapeId, std::vector<taxel::Contact<S>>> cache;
  auto& s = cache[shape];
  if (s.empty()) {
    std::vector<taxel::Contact<double>> c;
    const taxel::sim::SlidingConfig cfg{.seed = 42};
    switch (shape) {
      case ShapeId::sphere:
        c = taxel::sim::sliding_exploration(taxel::sim::Sphere(0.04), kStream, cfg);
        break;
      case ShapeId::cylinder:
        c = taxel::sim::sliding_exploration(taxel::sim::Cylinder(0.03, 0.05), kStream, cfg);
        break;
      case ShapeId::box:
        c = taxel::sim::sliding_exploration(taxel::sim::Box(), kStream, cfg);
        break;
    }
    for (const auto& x : c) s.push_back(taxel::contact_cast<S>(x));
  }
  return s;
}

// Contacts per second (and its inverse, ns per contact) and the points of the last cloud.
void per_contact_counters(benchmark::State& state, std::size_t contacts, std::size_t points) {
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * contacts));
  state.counters["ns_per_contact"] =
      benchmark::Counter(static_cast<double>(state.iterations() * contacts),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["points"] = static_cast<double>(points);
}

// End to end: a fresh cloud per iteration, the whole stream inserted.
template <class Policy, class Index>
void Fuse(benchmark::State& state) {
  using S = typename Policy::Scalar;
  const auto& contacts = stream<S>(static_cast<ShapeId>(state.range(0)));
  std::size_t points = 0, bytes = 0, fused = 0;
  for (auto _ : state) {
    using Cloud = tf::ContactCloud<Policy, Index>;
    Cloud cloud(fixed_gate<Cloud>());
    for (const auto& c : contacts) benchmark::DoNotOptimize(cloud.insert(c));
    points = cloud.size();
    bytes = cloud.memory_bytes();
    fused = contacts.size() - points;
    benchmark::ClobberMemory();
  }
  per_contact_counters(state, contacts.size(), points);
  state.counters["bytes_per_point"] = static_cast<double>(bytes) / static_cast<double>(points);
  state.counters["fused_pct"] = 100.0 * static_cast<double>(fused) / double(contacts.size());
}

// The default gate on the same streams: a contact with no point within 2 mm looks again within
// 6 sigma of its noise along the normal (about 6 mm here). Fewer, better points; a wider query
// for the contacts that find none within the radius.
template <class Policy>
void FuseWidenedGate(benchmark::State& state) {
  const auto& contacts = stream<double>(static_cast<ShapeId>(state.range(0)));
  std::size_t points = 0;
  for (auto _ : state) {
    tf::ContactCloud<Policy, ti::VoxelHash<double>> cloud({.association_radius = kRadius});
    for (const auto& c : contacts) benchmark::DoNotOptimize(cloud.insert(c));
    points = cloud.size();
    benchmark::ClobberMemory();
  }
  per_contact_counters(state, contacts.size(), points);
}

// Query only: nearest_within for every contact against a finished cloud's index.
template <class Index>
void QueryReplay(benchmark::State& state) {
  using S = typename Index::Scalar;
  const auto& contacts = stream<S>(static_cast<ShapeId>(state.range(0)));
  using Cloud = tf::ContactCloud<tf::Kalman<S>, Index>;
  Cloud cloud(fixed_gate<Cloud>());
  for (const auto& c : contacts) cloud.insert(c);
  for (auto _ : state) {
    for (const auto& c : contacts) {
      benchmark::DoNotOptimize(cloud.index().nearest_within(c.position, S(kRadius)));
    }
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * contacts.size()));
  state.counters["points"] = static_cast<double>(cloud.size());
}

// Growth: 100k contacts spread over a 0.5 m cube, almost all of them new points.
template <class Index>
void Growth(benchmark::State& state) {
  using S = typename Index::Scalar;
  std::vector<taxel::Contact<S>> contacts(100000);
  std::mt19937 rng(1);
  std::uniform_real_distribution<S> u(S(-0.25), S(0.25));
  for (auto& c : contacts) c.position = {u(rng), u(rng), u(rng)};
  std::size_t points = 0;
  for (auto _ : state) {
    using Cloud = tf::ContactCloud<tf::Kalman<S>, Index>;
    Cloud cloud(fixed_gate<Cloud>());
    for (const auto& c : contacts) benchmark::DoNotOptimize(cloud.insert(c));
    points = cloud.size();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * contacts.size()));
  state.counters["points"] = static_cast<double>(points);
}

// With --benchmark_repetitions, the fastest repetition beside the median: on a shared machine
// the minimum is the least disturbed run.
double fastest(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }

void Shapes(benchmark::internal::Benchmark* b) {
  b->ArgName("shape")->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
  b->ComputeStatistics("min", fastest);
}

}  // namespace

// One line per combination; a new policy or index is one more line.
BENCHMARK_TEMPLATE(Fuse, tf::Surfel<double>, ti::VoxelHash<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Kalman<double>, ti::VoxelHash<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Kalman<float>, ti::VoxelHash<float>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Kalman<double>, ti::DynamicKdTree<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Kalman<double>, ti::BruteForce<double>)->Apply(Shapes)->Iterations(1);
BENCHMARK_TEMPLATE(Fuse, tf::Average<double>, ti::VoxelHash<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Average<double>, ti::DynamicKdTree<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Average<double>, ti::BruteForce<double>)->Apply(Shapes)->Iterations(1);
BENCHMARK_TEMPLATE(Fuse, tf::Raw<double>, ti::VoxelHash<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Raw<double>, ti::DynamicKdTree<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(Fuse, tf::Raw<double>, ti::BruteForce<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(FuseWidenedGate, tf::Kalman<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(FuseWidenedGate, tf::Surfel<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(QueryReplay, ti::VoxelHash<double>)->Apply(Shapes);
BENCHMARK_TEMPLATE(QueryReplay, ti::DynamicKdTree<double>)->Apply(Shapes);
namespace {

// Frames of the pad model: a 14x6 pad sliding, a 3-finger hand grasping and a fingertip
// palpating (sim/exploration.hpp), one contact per active tactel, gate 4 mm as in the fusion
// study. The contacts in stream order and where each frame (all pads of one time step) ends.
struct Frames {
  std::vector<taxel::Contact<double>> contacts;
  std::vector<std::size_t> ends;
};

const Frames& pad_frames(ShapeId shape) {
  static std::map<ShapeId, Frames> cache;
  Frames& f = cache[shape];
  if (!f.contacts.empty()) return f;
  taxel::sim::ExplorationConfig cfg;
  cfg.seed = 7;
  const auto add = [&](const auto& ex) {
    for (const auto& frame : ex.frames) {
      if (frame.contacts.empty()) continue;
      f.contacts.insert(f.contacts.end(), frame.contacts.begin(), frame.contacts.end());
      f.ends.push_back(f.contacts.size());
    }
  };
  const auto explore = [&](const auto& s) {
    add(taxel::sim::explore_sliding(s, cfg, {.slides = 4, .frames = 1000}));
    add(taxel::sim::explore_grasps(s, cfg, {.grasps = 8}));
    add(taxel::sim::explore_palpation(s, cfg, {.touches = 40}));
  };
  switch (shape) {
    case ShapeId::sphere:
      explore(taxel::sim::Sphere(0.04));
      break;
    case ShapeId::cylinder:
      explore(taxel::sim::Cylinder(0.03, 0.05));
      break;
    case ShapeId::box:
      explore(taxel::sim::Box(taxel::Vec3d(0.04, 0.03, 0.02)));
      break;
  }
  return f;
}

constexpr double kPadGate = 4e-3;

void frame_counters(benchmark::State& state, const Frames& f, std::size_t points) {
  per_contact_counters(state, f.contacts.size(), points);
  state.counters["per_frame"] = double(f.contacts.size()) / double(f.ends.size());
}

// ContactCloud, one contact at a time (the baseline for the frame insert).
template <class Policy>
void PadOneByOne(benchmark::State& state) {
  const Frames& f = pad_frames(static_cast<ShapeId>(state.range(0)));
  std::size_t points = 0;
  for (auto _ : state) {
    tf::ContactCloud<Policy, ti::VoxelHash<double>> cloud({.association_radius = kPadGate});
    for (const auto& c : f.contacts) benchmark::DoNotOptimize(cloud.insert(c));
    points = cloud.size();
    benchmark::ClobberMemory();
  }
  frame_counters(state, f, points);
}

// ContactCloud, a frame at a time (insert_frame).
template <class Policy>
void PadFrames(benchmark::State& state) {
  const Frames& f = pad_frames(static_cast<ShapeId>(state.range(0)));
  std::size_t points = 0;
  const std::span<const taxel::Contact<double>> all(f.contacts);
  for (auto _ : state) {
    tf::ContactCloud<Policy, ti::VoxelHash<double>> cloud({.association_radius = kPadGate});
    std::size_t begin = 0;
    for (const std::size_t end : f.ends) {
      benchmark::DoNotOptimize(cloud.insert(all.subspan(begin, end - begin)));
      begin = end;
    }
    points = cloud.size();
    benchmark::ClobberMemory();
  }
  frame_counters(state, f, points);
}

#ifdef TAXEL_BENCH_HAVE_ROBIN_MAP
// The reference hash grid (reference_grid.hpp), same policy, same stream.
template <class Policy>
void PadReferenceGrid(benchmark::State& state) {
  const Frames& f = pad_frames(static_cast<ShapeId>(state.range(0)));
  std::size_t points = 0;
  for (auto _ : state) {
    taxel_bench::ReferenceGrid<Policy> grid(kPadGate);
    for (const auto& c : f.contacts) grid.insert(c);
    points = grid.size();
    benchmark::ClobberMemory();
  }
  // Same cloud as ContactCloud's, or the comparison means nothing.
  tf::ContactCloud<Policy, ti::VoxelHash<double>> cloud({.association_radius = kPadGate});
  for (const auto& c : f.contacts) (void)cloud.insert(c);
  if (cloud.size() != points) state.SkipWithError("reference grid and ContactCloud differ");
  frame_counters(state, f, points);
}

// The reference grid on the 200k-contact sliding streams (gate 2 mm), beside Fuse.
template <class Policy>
void FuseReferenceGrid(benchmark::State& state) {
  const auto& contacts = stream<double>(static_cast<ShapeId>(state.range(0)));
  std::size_t points = 0;
  for (auto _ : state) {
    taxel_bench::ReferenceGrid<Policy> grid(kRadius);
    for (const auto& c : contacts) grid.insert(c);
    points = grid.size();
    benchmark::ClobberMemory();
  }
  per_contact_counters(state, contacts.size(), points);
}
#endif

void PadShapes(benchmark::internal::Benchmark* b) {
  b->ArgName("shape")->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);
  b->ComputeStatistics("min", fastest);
}

}  // namespace

BENCHMARK_TEMPLATE(PadOneByOne, tf::Kalman<double>)->Apply(PadShapes);
BENCHMARK_TEMPLATE(PadFrames, tf::Kalman<double>)->Apply(PadShapes);
#ifdef TAXEL_BENCH_HAVE_ROBIN_MAP
BENCHMARK_TEMPLATE(PadReferenceGrid, tf::Kalman<double>)->Apply(PadShapes);
BENCHMARK_TEMPLATE(FuseReferenceGrid, tf::Kalman<double>)->Apply(PadShapes);
#endif
BENCHMARK_TEMPLATE(PadOneByOne, tf::Surfel<double>)->Apply(PadShapes);
BENCHMARK_TEMPLATE(PadFrames, tf::Surfel<double>)->Apply(PadShapes);
#ifdef TAXEL_BENCH_HAVE_ROBIN_MAP
BENCHMARK_TEMPLATE(PadReferenceGrid, tf::Surfel<double>)->Apply(PadShapes);
#endif

BENCHMARK_TEMPLATE(Growth, ti::VoxelHash<double>)->Unit(benchmark::kMillisecond);
BENCHMARK_TEMPLATE(Growth, ti::DynamicKdTree<double>)->Unit(benchmark::kMillisecond);

// Readings to contacts (sensor::ContactExtractor): the frames of a pad sliding over a sphere
// and a box, per tactel and per pad; time per active tactel.
void ReadingsToContacts(benchmark::State& state) {
  const bool per_pad = state.range(1) != 0;
  static std::map<int, std::vector<taxel::sim::PadReading>> cache;
  auto& frames = cache[int(state.range(0))];
  taxel::sim::ExplorationConfig cfg;
  if (frames.empty()) {
    const auto collect = [&](const auto& ex) {
      for (const auto& f : ex.frames)
        for (const auto& p : f.pads) frames.push_back(p);
    };
    if (state.range(0) == 0) {
      collect(taxel::sim::explore_sliding(taxel::sim::Sphere(0.04), cfg, {.frames = 500}));
    } else {
      collect(taxel::sim::explore_sliding(taxel::sim::Box(), cfg, {.frames = 500}));
    }
  }
  taxel::sensor::ContactExtractor extractor(
      cfg.sensor, {.mode = per_pad ? taxel::sensor::ContactMode::per_pad
                                   : taxel::sensor::ContactMode::per_tactel});
  std::vector<taxel::Contact<double>> out;
  out.reserve(frames.size() * 84);
  std::size_t active = 0;
  const auto lo = static_cast<std::uint16_t>(cfg.sensor.threshold);
  const auto hi = static_cast<std::uint16_t>(cfg.sensor.levels - 1);
  for (const auto& f : frames) active += std::size_t((f.counts >= lo && f.counts < hi).count());
  for (auto _ : state) {
    out.clear();
    for (const auto& f : frames) extractor.extract(f.counts, f.believed_pose, 0.0, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["ns_per_active_tactel"] =
      benchmark::Counter(static_cast<double>(state.iterations() * active),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["active_per_frame"] = double(active) / double(frames.size());
}
BENCHMARK(ReadingsToContacts)->ArgsProduct({{0, 1}, {0, 1}})->ArgNames({"box", "per_pad"});

BENCHMARK_MAIN();
