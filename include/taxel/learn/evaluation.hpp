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
#include <numeric>
#include <random>
#include <span>
#include <string>
#include <vector>

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
  ProgressFn progress{};                                    ///< called after each fold
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
template <Classifier C>
Outcome train_and_test(const C& prototype, const DatasetView& d, std::span<const int> fold, int f,
                       double snr_db, NoiseTarget target, std::mt19937_64& rng,
                       std::vector<int>& predicted) {
  std::vector<std::size_t> train;
  std::vector<std::size_t> test;
  for (std::size_t i = 0; i < fold.size(); ++i) (fold[i] == f ? test : train).push_back(i);
  Dataset tr = subset(d, train);
  Dataset te = subset(d, test);
  if (std::isfinite(snr_db)) {
    if (target == NoiseTarget::both) add_white_noise(tr.x, snr_db, rng);
    add_white_noise(te.x, snr_db, rng);
  }
  C model = prototype;
  Outcome o = model.fit(tr.view());
  if (o.status != Status::ok && o.status != Status::not_converged) return o;
  for (std::size_t r = 0; r < test.size(); ++r) {
    predicted[test[r]] = model.predict(te.x.row(static_cast<Eigen::Index>(r)).transpose());
  }
  return o;
}
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
  std::mt19937_64 rng(opt.seed ^ 0x9e3779b97f4a7c15ULL);
  for (int f = 0; f < opt.folds; ++f) {
    const Outcome o = detail::train_and_test(prototype, d, rep.fold, f, opt.snr_db,
                                             opt.noise_target, rng, rep.predicted);
    if (o.status == Status::not_converged && rep.ok()) {
      rep.status = o.status;
      rep.message = "fold " + std::to_string(f + 1) + ": " + o.message;
    } else if (!o && o.status != Status::not_converged) {
      rep.status = o.status;
      rep.message = "fold " + std::to_string(f + 1) + ": " + o.message;
      return rep;
    }
    if (opt.progress)
      opt.progress(static_cast<std::size_t>(f + 1), static_cast<std::size_t>(opt.folds));
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
  ProgressFn progress{};  ///< called after each of the 10 train/test rounds
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
  FiveByTwoDifferences diff{};
  double err_a = 0.0;
  double err_b = 0.0;
  std::vector<int> pred_a(d.y.size());
  std::vector<int> pred_b(d.y.size());
  std::size_t round = 0;
  for (int rep = 0; rep < 5; ++rep) {
    auto folds = kfold_assignment(d.y, 2, opt.seed + static_cast<std::uint64_t>(rep) * 7919U,
                                  opt.grouped ? d.groups : std::span<const int>{});
    if (!folds) {
      static_cast<Outcome&>(fail) = folds;
      return fail;
    }
    for (int f = 0; f < 2; ++f) {
      // Same noise for both: one generator state per round, copied.
      std::mt19937_64 noise(opt.seed * 31U + static_cast<std::uint64_t>(rep * 2 + f));
      std::mt19937_64 noise_b = noise;
      const Outcome oa =
          detail::train_and_test(a, d, folds.value, f, opt.snr_db, opt.noise_target, noise, pred_a);
      const Outcome ob = detail::train_and_test(b, d, folds.value, f, opt.snr_db, opt.noise_target,
                                                noise_b, pred_b);
      for (const Outcome* o : {&oa, &ob}) {
        if (!*o && o->status != Status::not_converged) {
          static_cast<Outcome&>(fail) = *o;
          fail.message = "replication " + std::to_string(rep + 1) + ", fold " +
                         std::to_string(f + 1) + ": " + o->message;
          return fail;
        }
      }
      std::size_t n_test = 0;
      std::size_t wrong_a = 0;
      std::size_t wrong_b = 0;
      for (std::size_t i = 0; i < d.y.size(); ++i) {
        if (folds.value[i] != f) continue;
        ++n_test;
        wrong_a += pred_a[i] != d.y[i] ? 1 : 0;
        wrong_b += pred_b[i] != d.y[i] ? 1 : 0;
      }
      const double ea = static_cast<double>(wrong_a) / static_cast<double>(n_test);
      const double eb = static_cast<double>(wrong_b) / static_cast<double>(n_test);
      diff[static_cast<std::size_t>(rep)][static_cast<std::size_t>(f)] = ea - eb;
      err_a += ea / 10.0;
      err_b += eb / 10.0;
      if (opt.progress) opt.progress(++round, 10);
    }
  }
  FiveByTwoResult r = five_by_two_t_test(diff, opt.alpha);
  r.mean_error_a = err_a;
  r.mean_error_b = err_b;
  return r;
}

}  // namespace taxel::learn
