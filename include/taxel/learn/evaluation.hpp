// SPDX-License-Identifier: MIT
// Evaluation of classifiers: stratified (optionally grouped) K-fold splits, cross-validation
// with per-class accuracy and confusion matrix, feature noise at a given SNR, and the 5x2cv
// paired t test of two classifiers.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <mutex>
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "taxel/core/parallel.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/concepts.hpp"
#include "taxel/learn/dataset.hpp"
#include "taxel/learn/stats.hpp"

namespace taxel::learn {

/// Called after each unit of work with (done, total); for progress displays. Headers never
/// print: the caller decides where progress goes.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

/// Fold number (0..k-1) of every sample. Without groups the split is stratified: each class
/// is shuffled (seeded) and dealt round-robin, so every fold holds each class in proportion and
/// fold sizes differ by at most one. With `groups` (one id per sample), every group stays in
/// one fold: groups are shuffled, then placed largest first into the fold with the fewest
/// samples. Returns `invalid_input` for k < 2, k above the number of samples (or groups), or a
/// group list of the wrong length.
template <class = void>
inline Result<std::vector<int>> kfold_assignment(std::span<const int> y, int k, std::uint64_t seed,
                                                 std::span<const int> groups = {}) {
  using R = Result<std::vector<int>>;
  const std::size_t n = y.size();
  if (k < 2)
    return R::failure(Status::invalid_input,
                      "kfold: need at least 2 folds, got " + std::to_string(k));
  if (static_cast<std::size_t>(k) > n) {
    return R::failure(Status::invalid_input, "kfold: " + std::to_string(k) + " folds but only " +
                                                 std::to_string(n) + " samples");
  }
  std::mt19937_64 rng(seed);
  std::vector<int> fold(n, 0);
  if (groups.empty()) {
    std::size_t dealt = 0;
    for (int label : class_order(y)) {
      std::vector<std::size_t> members;
      for (std::size_t i = 0; i < n; ++i) {
        if (y[i] == label) members.push_back(i);
      }
      std::shuffle(members.begin(), members.end(), rng);
      for (std::size_t i : members)
        fold[i] = static_cast<int>(dealt++ % static_cast<std::size_t>(k));
    }
    return R::success(std::move(fold));
  }
  if (groups.size() != n) {
    return R::failure(Status::invalid_input, "kfold: " + std::to_string(n) + " samples but " +
                                                 std::to_string(groups.size()) + " group ids");
  }
  std::vector<int> ids(groups.begin(), groups.end());
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  if (ids.size() < static_cast<std::size_t>(k)) {
    return R::failure(Status::invalid_input, "kfold: " + std::to_string(k) + " folds but only " +
                                                 std::to_string(ids.size()) + " groups");
  }
  std::vector<std::size_t> size(ids.size(), 0);
  for (int g : groups) {
    ++size[static_cast<std::size_t>(std::lower_bound(ids.begin(), ids.end(), g) - ids.begin())];
  }
  std::vector<std::size_t> order(ids.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::shuffle(order.begin(), order.end(), rng);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return size[a] > size[b]; });
  std::vector<std::size_t> load(static_cast<std::size_t>(k), 0);
  std::vector<int> group_fold(ids.size(), 0);
  for (std::size_t g : order) {
    const auto f =
        static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    group_fold[g] = static_cast<int>(f);
    load[f] += size[g];
  }
  for (std::size_t i = 0; i < n; ++i) {
    fold[i] = group_fold[static_cast<std::size_t>(
        std::lower_bound(ids.begin(), ids.end(), groups[i]) - ids.begin())];
  }
  return R::success(std::move(fold));
}

/// Options of cross_validate.
struct CvOptions {
  int folds = 5;           ///< K
  std::uint64_t seed = 1;  ///< fold shuffle (and noise) seed
  bool grouped = false;    ///< keep each group (DatasetView::groups) in one fold
  double snr_db = std::numeric_limits<double>::infinity();  ///< feature noise; inf = none
  NoiseTarget noise_target = NoiseTarget::test_only;        ///< where the noise goes
  /// Folds trained at once, each on its own thread (0: every core). The report does not depend
  /// on it: the noise is drawn in fold order before training. A classifier that trains on
  /// threads of its own (ThreadedTraining: `LinearSvm`) keeps them, so that the last folds do
  /// not leave cores idle, but at most this many: 1 runs everything on the calling thread.
  unsigned threads = 0;
  ProgressFn progress{};  ///< called after each fold (from the thread that ran it, serialised)
};

/// Cross-validated accuracy.
struct CvReport : Outcome {
  std::vector<int> classes;            ///< labels, in class_order of the data
  Eigen::MatrixXi confusion;           ///< [true class][predicted class], in `classes` order
  Eigen::VectorXd per_class_accuracy;  ///< recall of each class
  double accuracy = 0.0;               ///< fraction of samples predicted right
  std::vector<int> predicted;          ///< the out-of-fold prediction of every sample
  std::vector<int> fold;               ///< the fold of every sample
};

namespace detail {

/// One train/test split, its noise already added: what a fold needs to run on its own thread.
struct Split {
  Dataset train, test;
  std::vector<std::size_t> test_rows;  ///< the test samples' rows in the full data set
};

/// The split of fold `f` (test) against the other folds (train), with feature noise drawn from
/// `rng` when snr_db is finite: the test features, and the training features too for `both`.
template <class = void>
Split make_split(const DatasetView& d, std::span<const int> fold, int f, double snr_db,
                 NoiseTarget target, std::mt19937_64& rng) {
  std::vector<std::size_t> train;
  Split s;
  for (std::size_t i = 0; i < fold.size(); ++i) (fold[i] == f ? s.test_rows : train).push_back(i);
  s.train = subset(d, train);
  s.test = subset(d, s.test_rows);
  if (std::isfinite(snr_db)) {
    if (target == NoiseTarget::both) add_white_noise(s.train.x, snr_db, rng);
    add_white_noise(s.test.x, snr_db, rng);
  }
  return s;
}

/// Trains a copy of `prototype` on the split and writes its test predictions to
/// predicted[test row]. Returns the training outcome. A classifier with threads of its own
/// gets at most `threads` of them (0: no cap; see ThreadedTraining).
template <Classifier C>
Outcome train_and_test(const C& prototype, const Split& s, std::vector<int>& predicted,
                       unsigned threads) {
  C model = prototype;
  if constexpr (ThreadedTraining<C>) {
    const unsigned own = model.threads();
    if (threads > 0 && (own == 0 || own > threads)) model.set_threads(threads);
  }
  Outcome o = model.fit(s.train.view());
  if (o.status != Status::ok && o.status != Status::not_converged) return o;
  for (std::size_t r = 0; r < s.test_rows.size(); ++r) {
    predicted[s.test_rows[r]] =
        model.predict(s.test.x.row(static_cast<Eigen::Index>(r)).transpose());
  }
  return o;
}

/// Calls progress(done, total) after each unit, one call at a time, from any thread.
class Progress {
 public:
  Progress(const ProgressFn& fn, std::size_t total) : fn_(fn), total_(total) {}
  void step() {
    if (!fn_) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    fn_(++done_, total_);
  }

 private:
  const ProgressFn& fn_;
  std::size_t total_;
  std::size_t done_ = 0;
  std::mutex mutex_;
};

}  // namespace detail

/// K-fold cross-validation of a copy of `prototype` (trained afresh on each fold). A fold whose
/// training fails ends the run with that status; `not_converged` on some fold is reported in
/// the status while every number is still filled in.
template <Classifier C>
CvReport cross_validate(const C& prototype, const DatasetView& d, const CvOptions& opt = {}) {
  CvReport rep;
  Outcome check = validate_training_set(d, "cross_validate");
  if (!check) {
    static_cast<Outcome&>(rep) = check;
    return rep;
  }
  if (opt.grouped && d.groups.empty()) {
    rep.status = Status::invalid_input;
    rep.message = "cross_validate: grouped folds asked for, but the data set has no group ids";
    return rep;
  }
  auto folds =
      kfold_assignment(d.y, opt.folds, opt.seed, opt.grouped ? d.groups : std::span<const int>{});
  if (!folds) {
    static_cast<Outcome&>(rep) = folds;
    return rep;
  }
  rep.fold = std::move(folds.value);
  rep.classes = class_order(d.y);
  rep.predicted.assign(d.y.size(), 0);
  // Noise is drawn in fold order from one generator, so the splits (and the report) are the
  // same for any number of threads; the folds then train in parallel. Without noise each fold
  // makes its own split on its thread.
  const bool noisy = std::isfinite(opt.snr_db);
  std::mt19937_64 rng(opt.seed ^ 0x9e3779b97f4a7c15ULL);
  std::vector<detail::Split> splits(static_cast<std::size_t>(opt.folds));
  for (int f = 0; noisy && f < opt.folds; ++f) {
    splits[static_cast<std::size_t>(f)] =
        detail::make_split(d, rep.fold, f, opt.snr_db, opt.noise_target, rng);
  }
  std::vector<Outcome> outcomes(splits.size());
  detail::Progress progress(opt.progress, splits.size());
  parallel_for(splits.size(), opt.threads, [&](std::size_t f) {
    if (!noisy) {
      splits[f] = detail::make_split(d, rep.fold, static_cast<int>(f), opt.snr_db, opt.noise_target,
                                     rng);  // draws nothing without noise
    }
    outcomes[f] = detail::train_and_test(prototype, splits[f], rep.predicted, opt.threads);
    splits[f] = {};  // free the fold's copy of the data as soon as it is done
    progress.step();
  });
  for (std::size_t f = 0; f < outcomes.size(); ++f) {
    const Outcome& o = outcomes[f];
    if (o.status == Status::not_converged && rep.ok()) {
      rep.status = o.status;
      rep.message = "fold " + std::to_string(f + 1) + ": " + o.message;
    } else if (!o && o.status != Status::not_converged) {
      rep.status = o.status;
      rep.message = "fold " + std::to_string(f + 1) + ": " + o.message;
      return rep;
    }
  }
  const auto k = static_cast<Eigen::Index>(rep.classes.size());
  rep.confusion = Eigen::MatrixXi::Zero(k, k);
  std::size_t right = 0;
  for (std::size_t i = 0; i < d.y.size(); ++i) {
    const int t = class_index(rep.classes, d.y[i]);
    const int p = class_index(rep.classes, rep.predicted[i]);
    if (p >= 0) ++rep.confusion(t, p);
    right += d.y[i] == rep.predicted[i] ? 1 : 0;
  }
  rep.accuracy = static_cast<double>(right) / static_cast<double>(d.y.size());
  rep.per_class_accuracy.resize(k);
  for (Eigen::Index c = 0; c < k; ++c) {
    const int total = rep.confusion.row(c).sum();
    rep.per_class_accuracy(c) = total > 0 ? static_cast<double>(rep.confusion(c, c)) / total : 0.0;
  }
  return rep;
}

/// Options of five_by_two_cv.
struct FiveByTwoOptions {
  double alpha = 0.05;     ///< significance level of the two-sided test
  std::uint64_t seed = 1;  ///< seeds the five 2-fold splits (and noise)
  bool grouped = false;    ///< keep each group in one half
  double snr_db = std::numeric_limits<double>::infinity();  ///< feature noise; inf = none
  NoiseTarget noise_target = NoiseTarget::test_only;        ///< where the noise goes
  /// Rounds run at once, each on its own thread (0: every core); also the most threads a
  /// classifier with threads of its own (ThreadedTraining) gets: 1 runs everything on the
  /// calling thread.
  unsigned threads = 0;
  ProgressFn progress{};  ///< called after each of the 10 train/test rounds (serialised)
};

/// Dietterich's 5x2cv paired t test: five replications of a stratified 2-fold split; both
/// classifiers train on the same half and are tested on the other; the differences of their
/// error rates feed five_by_two_t_test. Both see the same noisy features.
template <Classifier A, Classifier B>
FiveByTwoResult five_by_two_cv(const A& a, const B& b, const DatasetView& d,
                               const FiveByTwoOptions& opt = {}) {
  FiveByTwoResult fail;
  fail.alpha = opt.alpha;
  Outcome check = validate_training_set(d, "five_by_two_cv");
  if (!check) {
    static_cast<Outcome&>(fail) = check;
    return fail;
  }
  // The ten rounds (5 replications x 2 folds) are independent: each has its own split and its
  // own noise generator, so they run in parallel with results independent of the thread count.
  std::vector<std::vector<int>> folds(5);
  for (int rep = 0; rep < 5; ++rep) {
    auto f = kfold_assignment(d.y, 2, opt.seed + static_cast<std::uint64_t>(rep) * 7919U,
                              opt.grouped ? d.groups : std::span<const int>{});
    if (!f) {
      static_cast<Outcome&>(fail) = f;
      return fail;
    }
    folds[static_cast<std::size_t>(rep)] = std::move(f.value);
  }
  struct Round {
    Outcome a, b;
    double error_a = 0.0, error_b = 0.0;
  };
  std::vector<Round> rounds(10);
  detail::Progress progress(opt.progress, rounds.size());
  parallel_for(rounds.size(), opt.threads, [&](std::size_t k) {
    const int rep = static_cast<int>(k / 2);
    const int f = static_cast<int>(k % 2);
    const std::vector<int>& fold = folds[static_cast<std::size_t>(rep)];
    // Both classifiers see the same noisy features.
    std::mt19937_64 noise(opt.seed * 31U + static_cast<std::uint64_t>(rep * 2 + f));
    const detail::Split split = detail::make_split(d, fold, f, opt.snr_db, opt.noise_target, noise);
    std::vector<int> pred_a(d.y.size()), pred_b(d.y.size());
    Round& r = rounds[k];
    r.a = detail::train_and_test(a, split, pred_a, opt.threads);
    r.b = detail::train_and_test(b, split, pred_b, opt.threads);
    std::size_t wrong_a = 0, wrong_b = 0;
    for (const std::size_t i : split.test_rows) {
      wrong_a += pred_a[i] != d.y[i] ? 1 : 0;
      wrong_b += pred_b[i] != d.y[i] ? 1 : 0;
    }
    const auto n_test = static_cast<double>(split.test_rows.size());
    r.error_a = static_cast<double>(wrong_a) / n_test;
    r.error_b = static_cast<double>(wrong_b) / n_test;
    progress.step();
  });
  FiveByTwoDifferences diff{};
  double err_a = 0.0;
  double err_b = 0.0;
  for (std::size_t k = 0; k < rounds.size(); ++k) {
    for (const Outcome* o : {&rounds[k].a, &rounds[k].b}) {
      if (!*o && o->status != Status::not_converged) {
        static_cast<Outcome&>(fail) = *o;
        fail.message = "replication " + std::to_string(k / 2 + 1) + ", fold " +
                       std::to_string(k % 2 + 1) + ": " + o->message;
        return fail;
      }
    }
    diff[k / 2][k % 2] = rounds[k].error_a - rounds[k].error_b;
    err_a += rounds[k].error_a / 10.0;
    err_b += rounds[k].error_b / 10.0;
  }
  FiveByTwoResult r = five_by_two_t_test(diff, opt.alpha);
  r.mean_error_a = err_a;
  r.mean_error_b = err_b;
  return r;
}

}  // namespace taxel::learn
