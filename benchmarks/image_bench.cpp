// SPDX-License-Identifier: MIT
// Per-stage and whole-chain timings of the pressure-image pipeline on 32x32 images (target:
// the whole hybrid chain <= 20 us per image; the paper reports 0.502 s).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <taxel/image.hpp>
#include <taxel/learn/linear_svm.hpp>
#include <taxel/sim/palm_grasp.hpp>
#include <vector>

namespace {

namespace ti = taxel::image;

// A batch of 32x32 palm-grasp-like images with 8-bit levels: a palm with finger gaps, one or
// two pressure ridges or a smooth bump, and noise, so that every stage does real work.
std::vector<ti::ImageD> images() {
  std::mt19937 rng(42);
  std::normal_distribution<double> noise(0.0, 6.0);
  std::vector<ti::ImageD> out;
  for (int n = 0; n < 64; ++n) {
    ti::ImageD img = ti::ImageD::Zero(32, 32);
    const int kind = n % 4;
    for (int r = 0; r < 29; ++r) {
      for (int c = 4; c < 28; ++c) {
        if (r < 5 && (c % 6 == 3 || c % 6 == 4)) continue;
        double v = 70;
        if (kind == 1) v += 150 * std::exp(-0.5 * std::pow((r - 14.0) / 1.3, 2));
        if (kind == 2) {
          v += 150 * (std::exp(-0.5 * std::pow((r - 10.0) / 1.2, 2)) +
                      std::exp(-0.5 * std::pow((r - 21.0) / 1.2, 2)));
        }
        if (kind == 3) v += 90 * std::cos((c - 16.0) / 14.0);
        img(r, c) = std::clamp(std::round(v + noise(rng)), 0.0, 255.0);
      }
    }
    out.push_back(img);
  }
  return out;
}

const std::vector<ti::ImageD>& batch() {
  static const std::vector<ti::ImageD> b = images();
  return b;
}

void BM_KMeansHistogram(benchmark::State& state) {
  ti::Segmenter seg({}, 32, 32);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(seg.run(batch()[i++ % batch().size()]).kmeans.sse);
  }
}
BENCHMARK(BM_KMeansHistogram)->Name("Segment/histogram_kmeans+classes+bwareaopen");

void BM_KMeansSorted(benchmark::State& state) {
  ti::KMeans1d km(3, 1024);
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& img = batch()[i++ % batch().size()];
    benchmark::DoNotOptimize(km.fit({img.data(), static_cast<std::size_t>(img.size())}).sse);
  }
}
BENCHMARK(BM_KMeansSorted)->Name("KMeans1d/exact_sorted_1024");

void BM_KMeansLloyd(benchmark::State& state) {
  std::size_t i = 0;
  for (auto _ : state) {
    const auto& img = batch()[i++ % batch().size()];
    benchmark::DoNotOptimize(
        ti::kmeans1d_lloyd({img.data(), static_cast<std::size_t>(img.size())}, {.k = 3}).sse);
  }
}
BENCHMARK(BM_KMeansLloyd)->Name("KMeans1d/lloyd_kmeans++_1024");

void BM_RegionProps(benchmark::State& state) {
  std::vector<ti::Mask> masks;
  for (const auto& img : batch()) masks.push_back(ti::segment(img).high);
  ti::RegionAnalyzer a({.perimeter = state.range(0) != 0}, 32, 32);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(a.compute(masks[i++ % masks.size()]).convex_area);
}
BENCHMARK(BM_RegionProps)->Name("RegionProps/union")->Arg(0)->Arg(1)->ArgName("perimeter");

void BM_Sobel(benchmark::State& state) {
  ti::ImageD mag(32, 32), dir(32, 32), gx(32, 32), gy(32, 32);
  std::size_t i = 0;
  for (auto _ : state) {
    ti::gradient(batch()[i++ % batch().size()], mag, dir, gx, gy);
    benchmark::DoNotOptimize(mag.data());
  }
}
BENCHMARK(BM_Sobel)->Name("Gradient/sobel_magnitude_direction");

void BM_Reconstruct(benchmark::State& state) {
  std::vector<ti::Segmentation> segs;
  for (const auto& img : batch()) segs.push_back(ti::segment(img));
  ti::Reconstructor rec({}, {}, 32, 32);
  const bool edged = state.range(0) != 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const std::size_t k = i++ % segs.size();
    benchmark::DoNotOptimize(edged ? rec.rec_edged(segs[k]).data()
                                   : rec.rec_edgeless(batch()[k], segs[k]).data());
  }
}
BENCHMARK(BM_Reconstruct)->Name("Reconstruct")->Arg(1)->Arg(0)->ArgName("edged");

// The classifier of the chain: a linear SVM (LIBLINEAR's one-vs-rest) trained on the hybrid
// features of synthetic palm grasps of the four classes, as an application would deploy it.
const taxel::learn::LinearSvm& trained_svm() {
  static const taxel::learn::LinearSvm svm = [] {
    const taxel::sim::PalmGraspSynth synth({}, 11);
    const auto samples = synth.dataset(6, 4);
    ti::Recognizer<> rec(32, 32);
    taxel::learn::Dataset d;
    d.x.resize(static_cast<Eigen::Index>(samples.size()), 32 * 32 + ti::kRegionalFeatures);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      d.x.row(static_cast<Eigen::Index>(i)) = rec.recognize(samples[i].image).hybrid.transpose();
      d.y.push_back(static_cast<int>(samples[i].label));
    }
    taxel::learn::LinearSvm m({.max_iterations = 200});
    (void)m.fit(d.view());
    return m;
  }();
  return svm;
}

const std::vector<ti::ImageD>& palm_grasps() {
  static const std::vector<ti::ImageD> b = [] {
    const taxel::sim::PalmGraspSynth synth({}, 5);
    std::vector<ti::ImageD> out;
    for (const auto& s : synth.dataset(8, 2)) out.push_back(s.image);
    return out;
  }();
  return b;
}

// Everything per image: segmentation, descriptors, contour gradients, the edged/edgeless
// decision, the reconstruction, the hybrid vector and the SVM's label.
void BM_WholeChain(benchmark::State& state) {
  ti::Recognizer<ti::GradientThreshold, taxel::learn::LinearSvm> rec(32, 32, {}, {}, trained_svm());
  const std::vector<ti::ImageD>& imgs = state.range(0) == 0 ? batch() : palm_grasps();
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(rec.recognize(imgs[i++ % imgs.size()]).label);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_WholeChain)
    ->Name("Recognizer/whole_hybrid_chain_with_linear_svm")
    ->Arg(0)
    ->Arg(1)
    ->ArgName("palm_grasps");

// A stack of 1 000 palm-grasp images through recognize_all on 1 thread and on every core
// (arg: threads, 0 = all), the trained SVM included.
void BM_RecognizeStack(benchmark::State& state) {
  const ti::Recognizer<ti::GradientThreshold, taxel::learn::LinearSvm> rec(32, 32, {}, {},
                                                                           trained_svm());
  const std::vector<ti::ImageD>& imgs = palm_grasps();
  const std::size_t n = 1000;
  const auto threads = static_cast<unsigned>(state.range(0));
  for (auto _ : state) {
    const auto all = ti::recognize_all(
        rec, n, [&](std::size_t i) -> const ti::ImageD& { return imgs[i % imgs.size()]; }, threads);
    benchmark::DoNotOptimize(all.back().label);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
  state.counters["threads"] = taxel::resolve_threads(threads);
}
BENCHMARK(BM_RecognizeStack)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
