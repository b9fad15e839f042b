// SPDX-License-Identifier: MIT
// The Classifier concept every learner in taxel::learn models, so that cross-validation, the
// 5x2cv test and pipelines take any of them (or yours) at compile time.
#pragma once

#include <Eigen/Core>
#include <concepts>
#include <span>

#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// A trainable classifier.
/// - `fit(data)` trains on a DatasetView and returns an Outcome (`ok`, `not_converged` with a
///   usable last iterate, or `invalid_input` / `degenerate` with the reason; then the previous
///   model is kept).
/// - `predict(x)` returns the label of one sample; `decision(x, out)` writes one score per class
///   (in `classes()` order, larger is more likely). Both throw std::invalid_argument for a
///   sample of the wrong length or with non-finite features, and std::logic_error before fit.
/// - `classes()` lists the labels in the model's order; `dims()` the features it expects.
template <class C>
concept Classifier = std::copy_constructible<C> &&
    requires(C& c, const C& cc, const DatasetView& d, const SampleRef& x,
             Eigen::Ref<Eigen::VectorXd> out) {
  { c.fit(d) } -> std::convertible_to<Outcome>;
  { cc.predict(x) } -> std::convertible_to<int>;
  cc.decision(x, out);
  { cc.classes() } -> std::convertible_to<std::span<const int>>;
  { cc.dims() } -> std::convertible_to<Eigen::Index>;
};

/// A classifier that trains on threads of its own (`LinearSvm`: its one-vs-rest problems):
/// `threads()` is how many it may use (0: every core), `set_threads(n)` changes that.
/// Cross-validation and the 5x2cv test cap it at their own `threads`, so that `threads = 1`
/// runs everything on the calling thread.
template <class C>
concept ThreadedTraining = requires(C& c, const C& cc, unsigned n) {
  { cc.threads() } -> std::convertible_to<unsigned>;
  c.set_threads(n);
};

}  // namespace taxel::learn
