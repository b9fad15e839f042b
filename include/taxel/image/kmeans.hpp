// SPDX-License-Identifier: MIT
// 1-D k-means: the exact optimum by dynamic programming over sorted distinct values (Wang and
// Song 2011, "Ckmeans.1d.dp"), and Lloyd's algorithm with seeded k-means++ starts for comparison.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/status.hpp"

namespace taxel::image {

/// A 1-D clustering. Clusters are intervals of the value axis, numbered in ascending order of
/// their centroids. When the data hold fewer distinct values than asked for, `k < k_requested`
/// and `message` says so; the status stays `ok` because the clustering is still exact.
struct KMeans1dResult : Outcome {
  int k_requested = 0;             ///< the number of clusters asked for
  int k = 0;                       ///< clusters found: min(k_requested, distinct values)
  std::vector<double> centroids;   ///< ascending; size k
  std::vector<double> lower;       ///< smallest value of each cluster; size k
  std::vector<double> upper;       ///< largest value of each cluster; size k
  std::vector<std::size_t> sizes;  ///< number of values in each cluster; size k
  double sse = 0.0;                ///< within-cluster sum of squared deviations
  int iterations = 0;              ///< Lloyd iterations (0 for the exact solver)

  /// The cluster a value belongs to: the first cluster whose upper end is not below `v`, where
  /// ends are midway between neighbouring clusters. Exact for every clustered value.
  [[nodiscard]] int cluster_of(double v) const noexcept {
    for (int c = 0; c + 1 < k; ++c) {
      if (v <= 0.5 * (upper[c] + lower[c + 1])) return c;
    }
    return k - 1;
  }
};

/// Exact 1-D k-means workspace: merges equal values (through a hash table when there are few
/// distinct ones, by sorting otherwise), then solves
/// D_c(j) = min_i D_{c-1}(i-1) + SSE(i..j) by divide and conquer over monotone split points
/// (O(k m log m) for m distinct values; the last layer is a single O(m) scan). Buffers are kept
/// between calls, so fitting images of the same size allocates nothing after the first call.
/// Not thread-safe (a reused workspace); one per thread.
class KMeans1d {
 public:
  /// `k` clusters, 1 <= k <= 255. Throws std::invalid_argument otherwise.
  explicit KMeans1d(int k = 3, std::size_t expected_values = 0) : k_(k) {
    if (k < 1 || k > 255) {
      throw std::invalid_argument("KMeans1d: k = " + std::to_string(k) +
                                  " is outside the allowed range [1, 255]");
    }
    reserve(expected_values);
    result_.centroids.reserve(static_cast<std::size_t>(k));
    result_.lower.reserve(static_cast<std::size_t>(k));
    result_.upper.reserve(static_cast<std::size_t>(k));
    result_.sizes.reserve(static_cast<std::size_t>(k));
  }

  /// Preallocates for up to `n` values.
  void reserve(std::size_t n) {
    if (n > (std::size_t{1} << 40)) {
      throw std::invalid_argument("KMeans1d: cannot reserve for " + std::to_string(n) +
                                  " values (at most 2^40)");
    }
    keys_.reserve(std::bit_ceil(2 * few_cap(n)));
    counts_.reserve(std::bit_ceil(2 * few_cap(n)));
    few_.reserve(few_cap(n));
    sorted_.reserve(n);
    value_.reserve(n);
    weight_.reserve(n);
    prefix_w_.reserve(n + 1);
    prefix_s_.reserve(n + 1);
    prefix_q_.reserve(n + 1);
    prev_.reserve(n);
    cur_.reserve(n);
    split_.reserve(n * static_cast<std::size_t>(k_));
  }

  /// Number of clusters asked for.
  [[nodiscard]] int k() const noexcept { return k_; }

  /// The exact clustering of `values`. Empty input or a non-finite value gives
  /// `invalid_input` (k = 0).
  template <class = void>
  const KMeans1dResult& fit(std::span<const double> values) {
    for (double v : values) {
      if (!std::isfinite(v)) return fail("a value is not finite");
    }
    if (merge_few(values)) return solve();
    sorted_.assign(values.begin(), values.end());
    std::sort(sorted_.begin(), sorted_.end());
    value_.clear();
    weight_.clear();
    for (std::size_t i = 0; i < sorted_.size();) {
      std::size_t j = i;
      while (j < sorted_.size() && sorted_[j] == sorted_[i]) ++j;
      value_.push_back(sorted_[i]);
      weight_.push_back(static_cast<double>(j - i));
      i = j;
    }
    return solve();
  }

  /// The exact clustering of integer levels given as a histogram: `counts[i]` values equal to
  /// `first_level + i`. Faster than `fit` for quantised images (no sort).
  template <class = void>
  const KMeans1dResult& fit_histogram(std::span<const std::uint32_t> counts,
                                      double first_level = 0.0) {
    value_.clear();
    weight_.clear();
    for (std::size_t i = 0; i < counts.size(); ++i) {
      if (counts[i] == 0) continue;
      value_.push_back(first_level + static_cast<double>(i));
      weight_.push_back(static_cast<double>(counts[i]));
    }
    return solve();
  }

  /// The last result.
  [[nodiscard]] const KMeans1dResult& result() const noexcept { return result_; }

 private:
  const KMeans1dResult& fail(const char* why) {
    result_.status = Status::invalid_input;
    result_.message = why;
    result_.k_requested = k_;
    result_.k = 0;
    result_.centroids.clear();
    result_.lower.clear();
    result_.upper.clear();
    result_.sizes.clear();
    result_.sse = 0.0;
    result_.iterations = 0;
    return result_;
  }

  // Data with few distinct values (scaled sensor counts, quantised images): equal values are
  // merged in a small open-addressing table and only the distinct ones are sorted, instead of
  // sorting every value. Gives up (false) once more than n / 4 + 16 distinct values appear,
  // leaving the sort to `fit`. Fills value_ and weight_ as the sort would.
  template <class = void>
  bool merge_few(std::span<const double> values) {
    const std::size_t cap = few_cap(values.size());
    const std::size_t size = std::bit_ceil(2 * cap);
    const int shift = 64 - std::countr_zero(size);
    keys_.assign(size, kEmptyKey);
    counts_.assign(size, 0);
    std::uint64_t* keys = keys_.data();
    std::uint32_t* counts = counts_.data();
    std::size_t distinct = 0;
    for (const double v : values) {
      const std::uint64_t bits = std::bit_cast<std::uint64_t>(v + 0.0);  // -0 and +0: one key
      std::size_t i = static_cast<std::size_t>((bits * 0x9E3779B97F4A7C15ULL) >> shift);
      while (keys[i] != bits && keys[i] != kEmptyKey) i = (i + 1) & (size - 1);
      if (keys[i] == kEmptyKey) {
        if (++distinct > cap) return false;
        keys[i] = bits;
      }
      ++counts[i];
    }
    few_.clear();
    for (std::size_t i = 0; i < size; ++i) {
      if (keys[i] != kEmptyKey) few_.push_back({std::bit_cast<double>(keys[i]), counts[i]});
    }
    std::sort(few_.begin(), few_.end(),
              [](const Distinct& a, const Distinct& b) { return a.value < b.value; });
    value_.clear();
    weight_.clear();
    for (const Distinct& d : few_) {
      value_.push_back(d.value);
      weight_.push_back(static_cast<double>(d.count));
    }
    return true;
  }
  static std::size_t few_cap(std::size_t n) noexcept { return n / 4 + 16; }

  // SSE of distinct values a..b inclusive, from prefix sums of shifted values.
  [[nodiscard]] double cost(std::size_t a, std::size_t b) const noexcept {
    const double w = prefix_w_[b + 1] - prefix_w_[a];
    const double s = prefix_s_[b + 1] - prefix_s_[a];
    const double q = prefix_q_[b + 1] - prefix_q_[a];
    return std::max(0.0, q - s * s / w);
  }

  // Layer c (>= 1, 0-based): cur_[j] = min over i in [c, j] of prev_[i-1] + cost(i, j), for
  // j in [lo, hi], with the optimal i known to lie in [opt_lo, opt_hi].
  void layer(std::size_t c, std::size_t lo, std::size_t hi, std::size_t opt_lo,
             std::size_t opt_hi) {
    const std::size_t m = value_.size();
    const std::size_t mid = lo + (hi - lo) / 2;
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_i = std::max(opt_lo, c);
    for (std::size_t i = std::max(opt_lo, c); i <= std::min(mid, opt_hi); ++i) {
      const double v = prev_[i - 1] + cost(i, mid);
      if (v < best) {
        best = v;
        best_i = i;
      }
    }
    cur_[mid] = best;
    split_[c * m + mid] = static_cast<std::uint32_t>(best_i);
    if (mid > lo) layer(c, lo, mid - 1, opt_lo, best_i);
    if (mid < hi) layer(c, mid + 1, hi, best_i, opt_hi);
  }

  const KMeans1dResult& solve() {
    const std::size_t m = value_.size();
    if (m == 0) return fail("no values to cluster");
    const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(k_), m);

    // Prefix sums of values shifted by their weighted mean, against cancellation.
    double total_w = 0.0;
    double total_s = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      total_w += weight_[i];
      total_s += weight_[i] * value_[i];
    }
    const double shift = total_s / total_w;
    prefix_w_.assign(m + 1, 0.0);
    prefix_s_.assign(m + 1, 0.0);
    prefix_q_.assign(m + 1, 0.0);
    for (std::size_t i = 0; i < m; ++i) {
      const double d = value_[i] - shift;
      prefix_w_[i + 1] = prefix_w_[i] + weight_[i];
      prefix_s_[i + 1] = prefix_s_[i] + weight_[i] * d;
      prefix_q_[i + 1] = prefix_q_[i] + weight_[i] * d * d;
    }

    prev_.assign(m, 0.0);
    cur_.assign(m, 0.0);
    split_.assign(m * k, 0);
    for (std::size_t j = 0; j < m; ++j) prev_[j] = cost(0, j);
    for (std::size_t c = 1; c < k; ++c) {
      if (c + 1 == k) {
        // Only the full range matters in the last layer.
        double best = std::numeric_limits<double>::infinity();
        std::size_t best_i = c;
        for (std::size_t i = c; i < m; ++i) {
          const double v = prev_[i - 1] + cost(i, m - 1);
          if (v < best) {
            best = v;
            best_i = i;
          }
        }
        cur_[m - 1] = best;
        split_[c * m + (m - 1)] = static_cast<std::uint32_t>(best_i);
      } else {
        layer(c, c, m - 1, c, m - 1);
      }
      prev_.swap(cur_);
    }

    // Walk the split points back from the last value.
    result_.status = Status::ok;
    result_.message.clear();
    result_.k_requested = k_;
    result_.k = static_cast<int>(k);
    result_.centroids.assign(k, 0.0);
    result_.lower.assign(k, 0.0);
    result_.upper.assign(k, 0.0);
    result_.sizes.assign(k, 0);
    result_.sse = 0.0;
    result_.iterations = 0;
    std::size_t end = m - 1;
    for (std::size_t c = k; c-- > 0;) {
      const std::size_t begin = c == 0 ? 0 : split_[c * m + end];
      const double w = prefix_w_[end + 1] - prefix_w_[begin];
      const double s = prefix_s_[end + 1] - prefix_s_[begin];
      result_.centroids[c] = shift + s / w;
      result_.lower[c] = value_[begin];
      result_.upper[c] = value_[end];
      result_.sizes[c] = static_cast<std::size_t>(w);
      result_.sse += cost(begin, end);
      if (c > 0) end = begin - 1;
    }
    if (k < static_cast<std::size_t>(k_)) {
      result_.message = "only " + std::to_string(k) + " distinct value(s); asked for " +
                        std::to_string(k_) + " clusters";
    }
    return result_;
  }

  struct Distinct {
    double value;
    std::uint32_t count;
  };
  // A NaN pattern: never the bits of a finite value.
  static constexpr std::uint64_t kEmptyKey = 0x7FF8000000000001ULL;

  int k_;
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> counts_;
  std::vector<Distinct> few_;
  std::vector<double> sorted_, value_, weight_;
  std::vector<double> prefix_w_, prefix_s_, prefix_q_;
  std::vector<double> prev_, cur_;
  std::vector<std::uint32_t> split_;
  KMeans1dResult result_;
};

/// The exact k-means clustering of `values` (allocating convenience around `KMeans1d`).
template <class = void>
inline KMeans1dResult kmeans1d(std::span<const double> values, int k = 3) {
  KMeans1d solver(k, values.size());
  return solver.fit(values);
}

/// Options of Lloyd's algorithm.
struct LloydConfig {
  int k = 3;                 ///< clusters, 1..255
  std::uint64_t seed = 1;    ///< seed of the k-means++ start
  int max_iterations = 100;  ///< cap; hitting it gives `not_converged`
};

/// Lloyd's algorithm from a seeded k-means++ start: a local optimum, deterministic for a given
/// seed. Provided to compare against the exact solver; centroids are returned ascending. An
/// emptied cluster is re-seeded at the value farthest from its centroid.
template <class = void>
inline KMeans1dResult kmeans1d_lloyd(std::span<const double> values, const LloydConfig& cfg = {}) {
  if (cfg.k < 1 || cfg.k > 255) {
    throw std::invalid_argument("kmeans1d_lloyd: k = " + std::to_string(cfg.k) +
                                " is outside the allowed range [1, 255]");
  }
  if (cfg.max_iterations < 1) {
    throw std::invalid_argument("kmeans1d_lloyd: max_iterations must be >= 1");
  }
  KMeans1dResult r;
  r.k_requested = cfg.k;
  if (values.empty()) {
    r.status = Status::invalid_input;
    r.message = "no values to cluster";
    return r;
  }
  std::vector<double> x(values.begin(), values.end());
  for (double v : x) {
    if (!std::isfinite(v)) {
      r.status = Status::invalid_input;
      r.message = "a value is not finite";
      return r;
    }
  }
  std::sort(x.begin(), x.end());
  std::size_t distinct = 1;
  for (std::size_t i = 1; i < x.size(); ++i) distinct += x[i] != x[i - 1] ? 1 : 0;
  const std::size_t k = std::min<std::size_t>(static_cast<std::size_t>(cfg.k), distinct);

  // k-means++ start.
  std::mt19937_64 rng(cfg.seed);
  std::vector<double> c;
  c.push_back(x[std::uniform_int_distribution<std::size_t>(0, x.size() - 1)(rng)]);
  std::vector<double> d2(x.size());
  while (c.size() < k) {
    double total = 0.0;
    for (std::size_t i = 0; i < x.size(); ++i) {
      double best = std::numeric_limits<double>::infinity();
      for (double ci : c) best = std::min(best, (x[i] - ci) * (x[i] - ci));
      d2[i] = best;
      total += best;
    }
    double u = std::uniform_real_distribution<double>(0.0, total)(rng);
    std::size_t pick = 0;
    for (; pick + 1 < x.size(); ++pick) {
      if (d2[pick] > 0.0 && u <= d2[pick]) break;
      u -= d2[pick];
    }
    if (d2[pick] == 0.0) {  // rounding left us on an existing centre: take the farthest value
      pick = static_cast<std::size_t>(std::max_element(d2.begin(), d2.end()) - d2.begin());
    }
    c.push_back(x[pick]);
  }

  std::vector<std::size_t> assign(x.size(), 0);
  std::vector<double> sum(k);
  std::vector<std::size_t> count(k);
  bool converged = false;
  int it = 0;
  while (it < cfg.max_iterations) {
    ++it;
    std::sort(c.begin(), c.end());
    bool changed = false;
    std::fill(sum.begin(), sum.end(), 0.0);
    std::fill(count.begin(), count.end(), 0);
    for (std::size_t i = 0; i < x.size(); ++i) {
      std::size_t best = 0;
      for (std::size_t j = 1; j < k; ++j) {
        if (std::abs(x[i] - c[j]) < std::abs(x[i] - c[best])) best = j;
      }
      changed = changed || best != assign[i] || it == 1;
      assign[i] = best;
      sum[best] += x[i];
      ++count[best];
    }
    for (std::size_t j = 0; j < k; ++j) {
      if (count[j] > 0) {
        c[j] = sum[j] / static_cast<double>(count[j]);
        continue;
      }
      std::size_t far = 0;
      for (std::size_t i = 1; i < x.size(); ++i) {
        if (std::abs(x[i] - c[assign[i]]) > std::abs(x[far] - c[assign[far]])) far = i;
      }
      c[j] = x[far];
      changed = true;
    }
    if (!changed) {
      converged = true;
      break;
    }
  }

  // Report in ascending order of centroid (intervals, since assignment is by nearest centre).
  std::vector<std::size_t> order(k);
  for (std::size_t j = 0; j < k; ++j) order[j] = j;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return c[a] < c[b]; });
  std::vector<std::size_t> rank(k);
  for (std::size_t j = 0; j < k; ++j) rank[order[j]] = j;
  r.k = static_cast<int>(k);
  r.centroids.assign(k, 0.0);
  r.lower.assign(k, std::numeric_limits<double>::infinity());
  r.upper.assign(k, -std::numeric_limits<double>::infinity());
  r.sizes.assign(k, 0);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::size_t j = rank[assign[i]];
    r.lower[j] = std::min(r.lower[j], x[i]);
    r.upper[j] = std::max(r.upper[j], x[i]);
    ++r.sizes[j];
  }
  for (std::size_t j = 0; j < k; ++j) r.centroids[j] = c[order[j]];
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = x[i] - c[assign[i]];
    r.sse += d * d;
  }
  r.iterations = it;
  if (!converged) {
    r.status = Status::not_converged;
    r.message = "Lloyd's algorithm hit max_iterations";
  } else if (k < static_cast<std::size_t>(cfg.k)) {
    r.message = "only " + std::to_string(k) + " distinct value(s); asked for " +
                std::to_string(cfg.k) + " clusters";
  }
  return r;
}

}  // namespace taxel::image
