// SPDX-License-Identifier: MIT
// Data sets for classification: dense row-major features with integer labels (and optional
// group ids, so that frames of one subject or recording can be kept together), views over
// Eigen matrices, validation and LIBLINEAR's label order.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/status.hpp"

namespace taxel::learn {

/// Dense features, one sample per row.
using FeatureMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
/// One sample (a row of a FeatureMatrix, as a column vector).
using FeatureVector = Eigen::VectorXd;
/// Any contiguous sample: a FeatureVector, a row of a FeatureMatrix, a mapped buffer.
using SampleRef = Eigen::Ref<const Eigen::VectorXd>;

/// A non-owning view of a labelled data set: `x` has one row per sample and `y` one label per
/// row. `groups` is empty or holds one group id per row (subject, recording).
struct DatasetView {
  Eigen::Ref<const FeatureMatrix> x;  ///< Features, one sample per row.
  std::span<const int> y;             ///< One label per row.
  std::span<const int> groups{};      ///< Empty, or one group id per row.

  /// Number of samples.
  [[nodiscard]] Eigen::Index rows() const noexcept { return x.rows(); }
  /// Number of features per sample.
  [[nodiscard]] Eigen::Index dims() const noexcept { return x.cols(); }
};

/// An owning data set.
struct Dataset {
  FeatureMatrix x;          ///< one sample per row
  std::vector<int> y;       ///< one label per row
  std::vector<int> groups;  ///< empty, or one group id per row

  /// A view of the whole set.
  [[nodiscard]] DatasetView view() const { return DatasetView{x, y, groups}; }
  /// Number of samples.
  [[nodiscard]] Eigen::Index rows() const noexcept { return x.rows(); }
  /// Number of features per sample.
  [[nodiscard]] Eigen::Index dims() const noexcept { return x.cols(); }
};

/// The rows `index` of `d`, in that order (groups too when present).
template <class = void>
inline Dataset subset(const DatasetView& d, std::span<const std::size_t> index) {
  Dataset out;
  out.x.resize(static_cast<Eigen::Index>(index.size()), d.dims());
  out.y.resize(index.size());
  if (!d.groups.empty()) out.groups.resize(index.size());
  for (std::size_t r = 0; r < index.size(); ++r) {
    const auto i = static_cast<Eigen::Index>(index[r]);
    out.x.row(static_cast<Eigen::Index>(r)) = d.x.row(i);
    out.y[r] = d.y[index[r]];
    if (!d.groups.empty()) out.groups[r] = d.groups[index[r]];
  }
  return out;
}

/// Distinct labels in LIBLINEAR/LIBSVM order: by first appearance, except that a two-class set
/// with labels -1 and +1 where -1 comes first is ordered (+1, -1), so that the positive side of
/// a binary model is the +1 class.
inline std::vector<int> class_order(std::span<const int> y) {
  std::vector<int> labels;
  for (int v : y) {
    if (std::find(labels.begin(), labels.end(), v) == labels.end()) labels.push_back(v);
  }
  if (labels.size() == 2 && labels[0] == -1 && labels[1] == 1) std::swap(labels[0], labels[1]);
  return labels;
}

namespace detail {
/// "" when `classes` are distinct (as a model read from bytes must hold them), else the problem.
inline std::string classes_error(std::span<const int> classes) {
  for (std::size_t i = 0; i < classes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (classes[i] == classes[j]) return "label " + std::to_string(classes[i]) + " twice";
    }
  }
  return {};
}
}  // namespace detail

/// Position of `label` in `classes`, or -1.
inline int class_index(std::span<const int> classes, int label) noexcept {
  for (std::size_t c = 0; c < classes.size(); ++c) {
    if (classes[c] == label) return static_cast<int>(c);
  }
  return -1;
}

/// Checks a training set: at least one sample and one feature, one label (and group, when
/// given) per row, finite features, and at least `min_classes` distinct labels.
/// `who` prefixes the message (the classifier's name).
template <class = void>
inline Outcome validate_training_set(const DatasetView& d, const std::string& who,
                                     std::size_t min_classes = 2) {
  const auto fail = [&](std::string why) {
    return Outcome{Status::invalid_input, who + ": " + why};
  };
  if (d.rows() == 0) return fail("the training set is empty");
  if (d.dims() == 0) return fail("the training set has no features");
  if (static_cast<std::size_t>(d.rows()) != d.y.size()) {
    return fail(std::to_string(d.rows()) + " samples but " + std::to_string(d.y.size()) +
                " labels");
  }
  if (!d.groups.empty() && d.groups.size() != d.y.size()) {
    return fail(std::to_string(d.rows()) + " samples but " + std::to_string(d.groups.size()) +
                " group ids");
  }
  for (Eigen::Index r = 0; r < d.rows(); ++r) {
    for (Eigen::Index c = 0; c < d.dims(); ++c) {
      if (!std::isfinite(d.x(r, c))) {
        return fail("feature " + std::to_string(c + 1) + " of sample " + std::to_string(r + 1) +
                    " is not finite");
      }
    }
  }
  const std::size_t k = class_order(d.y).size();
  if (k < min_classes) {
    return fail("the training set has " + std::to_string(k) + " class" + (k == 1 ? "" : "es") +
                "; at least " + std::to_string(min_classes) + " are needed");
  }
  return {};
}

namespace detail {
/// Throws std::logic_error before training, std::invalid_argument unless `x` has `dims`
/// features.
template <class = void>
inline void check_sample_size(const SampleRef& x, Eigen::Index dims, const char* who) {
  if (dims == 0) throw std::logic_error(std::string(who) + ": the model is not trained");
  if (x.size() != dims) {
    throw std::invalid_argument(std::string(who) + ": the sample has " + std::to_string(x.size()) +
                                " features, the model was trained on " + std::to_string(dims));
  }
}
/// Throws like check_sample_size, and std::invalid_argument for a non-finite feature.
template <class = void>
inline void check_sample(const SampleRef& x, Eigen::Index dims, const char* who) {
  check_sample_size(x, dims, who);
  if (!x.allFinite()) {
    throw std::invalid_argument(std::string(who) + ": the sample has a non-finite feature");
  }
}
}  // namespace detail

}  // namespace taxel::learn
