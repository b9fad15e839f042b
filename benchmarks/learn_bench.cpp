// SPDX-License-Identifier: MIT
// LinearSvm training and prediction on dense four-class data of 11 and 1035 features (the
// second paper's conventional and hybrid vectors), beside LIBLINEAR 2.3 in the same binary when
// liblinear-dev is installed. Targets: training no slower than LIBLINEAR at the same C and eps
// with accuracy within 0.5 points; prediction <= 1 us per sample at 1035 features. Also
// cross-validation and the 5x2cv test on one thread and on every core.
#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <random>
#include <taxel/learn.hpp>
#include <vector>

#ifdef TAXEL_BENCH_HAVE_LIBLINEAR
#include <linear.h>
#endif

namespace {

namespace tl = taxel::learn;

// Four overlapping Gaussian classes: class means differ on a few features, the rest is noise,
// and everything lies roughly in [-1, 1] as after svm-scale. Held-out test set of 1000.
struct Problem {
  tl::Dataset train;
  tl::Dataset test;
};

tl::Dataset draw(int n, int dims, unsigned seed, const tl::FeatureMatrix& means) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 0.35);
  tl::Dataset d;
  d.x.resize(n, dims);
  for (int i = 0; i < n; ++i) {
    const int c = i % 4;
    for (int j = 0; j < dims; ++j) d.x(i, j) = means(c, j) + g(rng);
    d.y.push_back(c + 1);
  }
  return d;
}

const Problem& data_for(int dims) {
  static std::map<int, Problem> cache;
  auto it = cache.find(dims);
  if (it != cache.end()) return it->second;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  tl::FeatureMatrix means(4, dims);
  for (int c = 0; c < 4; ++c) {
    for (int j = 0; j < dims; ++j) means(c, j) = u(rng) * (j < 11 ? 1.0 : 0.1);
  }
  Problem p{draw(4000, dims, 1, means), draw(1000, dims, 2, means)};
  return cache.emplace(dims, std::move(p)).first->second;
}

double accuracy(const auto& predict, const tl::Dataset& d) {
  int right = 0;
  for (Eigen::Index i = 0; i < d.rows(); ++i)
    right += predict(i) == d.y[static_cast<std::size_t>(i)] ? 1 : 0;
  return 100.0 * right / static_cast<double>(d.rows());
}

void BM_LinearSvmTrain(benchmark::State& state) {
  const Problem& p = data_for(static_cast<int>(state.range(0)));
  tl::LinearSvm m;
  for (auto _ : state) {
    benchmark::DoNotOptimize(m.fit(p.train.view()));
  }
  int iters = 0;
  for (int it : m.info().iterations) iters += it;
  state.counters["outer_iterations"] = iters;
  state.counters["test_accuracy_pct"] =
      accuracy([&](Eigen::Index i) { return m.predict(p.test.x.row(i).transpose()); }, p.test);
}
BENCHMARK(BM_LinearSvmTrain)->Arg(11)->Arg(1035)->Unit(benchmark::kMillisecond);

void BM_LinearSvmPredict(benchmark::State& state) {
  const Problem& p = data_for(static_cast<int>(state.range(0)));
  tl::LinearSvm m;
  m.fit(p.train.view());
  Eigen::Index i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(m.predict(p.test.x.row(i).transpose()));
    i = i + 1 == p.test.rows() ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LinearSvmPredict)->Arg(11)->Arg(1035);

#ifdef TAXEL_BENCH_HAVE_LIBLINEAR
struct Sparse {
  std::vector<std::vector<feature_node>> rows;
  std::vector<feature_node*> ptr;
  std::vector<double> y;
  explicit Sparse(const tl::Dataset& d) {
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
      std::vector<feature_node> r;
      for (Eigen::Index j = 0; j < d.dims(); ++j) {
        if (d.x(i, j) != 0.0) r.push_back({static_cast<int>(j + 1), d.x(i, j)});
      }
      r.push_back({-1, 0.0});
      rows.push_back(std::move(r));
      y.push_back(d.y[static_cast<std::size_t>(i)]);
    }
    for (auto& r : rows) ptr.push_back(r.data());
  }
};

// LIBLINEAR's train() at its defaults (-s 1 -c 1 -e 0.1, no bias) on the dense rows of `s`.
model* liblinear_train(const tl::Dataset& d, Sparse& s) {
  set_print_string_function([](const char*) {});
  ::problem prob{static_cast<int>(d.rows()), static_cast<int>(d.dims()), s.y.data(), s.ptr.data(),
                 -1.0};
  parameter par{};
  par.solver_type = L2R_L2LOSS_SVC_DUAL;
  par.C = 1.0;
  par.eps = 0.1;
  return train(&prob, &par);
}

void BM_LiblinearTrain(benchmark::State& state) {
  const Problem& p = data_for(static_cast<int>(state.range(0)));
  Sparse s(p.train);
  model* m = nullptr;
  for (auto _ : state) {
    if (m != nullptr) free_and_destroy_model(&m);
    m = liblinear_train(p.train, s);
    benchmark::DoNotOptimize(m);
  }
  Sparse t(p.test);
  state.counters["test_accuracy_pct"] = accuracy(
      [&](Eigen::Index i) {
        return static_cast<int>(predict(m, t.ptr[static_cast<std::size_t>(i)]));
      },
      p.test);
  free_and_destroy_model(&m);
}
BENCHMARK(BM_LiblinearTrain)->Arg(11)->Arg(1035)->Unit(benchmark::kMillisecond);

void BM_LiblinearPredict(benchmark::State& state) {
  const Problem& p = data_for(static_cast<int>(state.range(0)));
  Sparse s(p.train);
  model* m = liblinear_train(p.train, s);
  Sparse t(p.test);
  std::size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(predict(m, t.ptr[i]));
    i = i + 1 == t.ptr.size() ? 0 : i + 1;
  }
  state.SetItemsProcessed(state.iterations());
  free_and_destroy_model(&m);
}
BENCHMARK(BM_LiblinearPredict)->Arg(11)->Arg(1035);
#endif

// Cross-validation of LinearSvm on the 1035-feature problem (args: folds, threads with 0 = every
// core, LinearSvm's own threads; threads 1 caps those at one too) and the 5x2cv test (10
// rounds) of LinearSvm against Lda. Folds alone would cap the speed-up of 5 folds on 2 cores at
// 5 / 3 = 1.67; with each fold's 4 binary problems on threads of their own, the 20 problems
// balance over the cores.
void BM_CrossValidate(benchmark::State& state) {
  const Problem& p = data_for(1035);
  const tl::CvOptions opt{.folds = static_cast<int>(state.range(0)),
                          .threads = static_cast<unsigned>(state.range(1))};
  tl::LinearSvmConfig svm;  // the third argument: its threads (1: the folds alone)
  svm.threads = static_cast<unsigned>(state.range(2));
  double acc = 0.0;
  for (auto _ : state) acc = tl::cross_validate(tl::LinearSvm(svm), p.train.view(), opt).accuracy;
  state.counters["cv_accuracy_pct"] = 100.0 * acc;
  state.counters["threads"] = taxel::resolve_threads(opt.threads);
}
BENCHMARK(BM_CrossValidate)
    ->Args({5, 1, 0})
    ->Args({5, 0, 0})
    ->Args({5, 0, 1})
    ->Args({10, 1, 0})
    ->Args({10, 0, 0})
    ->Args({10, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_FiveByTwo(benchmark::State& state) {
  const Problem& p = data_for(11);
  const tl::FiveByTwoOptions opt{.threads = static_cast<unsigned>(state.range(0))};
  for (auto _ : state) {
    benchmark::DoNotOptimize(tl::five_by_two_cv(tl::LinearSvm{}, tl::Lda{}, p.train.view(), opt).t);
  }
  state.counters["threads"] = taxel::resolve_threads(opt.threads);
}
BENCHMARK(BM_FiveByTwo)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
