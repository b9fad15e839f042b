// SPDX-License-Identifier: MIT
// A feed-forward network (one or two hidden layers, softmax output, cross-entropy loss) trained
// by mini-batch Adam or SGD with momentum, seeded and deterministic.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// Hidden-layer non-linearity.
enum class MlpActivation { tanh, relu };
/// Optimiser.
enum class MlpOptimizer { adam, sgd };

/// Options of Mlp. Scale the features first (Scaled<StandardScaler, Mlp>).
struct MlpConfig {
  std::vector<int> hidden{32};                     ///< one or two hidden layer widths, each >= 1
  MlpActivation activation = MlpActivation::tanh;  ///< Activation of the hidden layers.
  MlpOptimizer optimizer = MlpOptimizer::adam;     ///< Adam or SGD with momentum.
  double learning_rate = 1e-2;                     ///< step size, > 0
  double momentum = 0.9;                           ///< SGD momentum, [0, 1)
  double l2 = 1e-4;         ///< weight decay on the weights (not the biases), >= 0
  int epochs = 200;         ///< passes over the training set, >= 1
  int batch_size = 32;      ///< samples per step, >= 1
  double tolerance = 1e-5;  ///< stop when the epoch loss improves less for `patience` epochs
  int patience = 10;        ///< epochs without improvement before stopping
  std::uint64_t seed = 1;   ///< initial weights and batch order
};

/// Multi-layer perceptron classifier; decision values are class probabilities. Models
/// Classifier.
class Mlp {
 public:
  /// Throws std::invalid_argument for an option outside its range.
  explicit Mlp(MlpConfig cfg = {}) : cfg_(std::move(cfg)) {
    const auto bad = [](const std::string& f, double v, const char* range) {
      throw std::invalid_argument("MlpConfig: " + f + " = " + std::to_string(v) +
                                  " is outside the allowed range " + range);
    };
    if (cfg_.hidden.empty() || cfg_.hidden.size() > 2) {
      bad("hidden.size()", static_cast<double>(cfg_.hidden.size()), "[1, 2]");
    }
    for (int h : cfg_.hidden) {
      if (h < 1) bad("hidden width", h, "[1, inf)");
    }
    if (!(cfg_.learning_rate > 0.0)) bad("learning_rate", cfg_.learning_rate, "(0, inf)");
    if (!(cfg_.momentum >= 0.0 && cfg_.momentum < 1.0)) bad("momentum", cfg_.momentum, "[0, 1)");
    if (!(cfg_.l2 >= 0.0)) bad("l2", cfg_.l2, "[0, inf)");
    if (cfg_.epochs < 1) bad("epochs", cfg_.epochs, "[1, inf)");
    if (cfg_.batch_size < 1) bad("batch_size", cfg_.batch_size, "[1, inf)");
    if (!(cfg_.tolerance >= 0.0)) bad("tolerance", cfg_.tolerance, "[0, inf)");
    if (cfg_.patience < 1) bad("patience", cfg_.patience, "[1, inf)");
  }

  /// Trains from a seeded Glorot initialisation. `degenerate` (model unchanged) when the loss
  /// becomes non-finite: lower the learning rate or scale the features.
  template <class D = void>
  Outcome fit(const Deferred<DatasetView, D>& d) {
    using Matrix = Deferred<Eigen::MatrixXd, D>;
    using Vector = Deferred<Eigen::VectorXd, D>;
    Outcome o = validate_training_set(d, "Mlp");
    if (!o) return o;
    std::vector<int> classes = class_order(d.y);
    const auto k = static_cast<Eigen::Index>(classes.size());
    const Eigen::Index n = d.rows();
    std::vector<Eigen::Index> widths{d.dims()};
    for (int h : cfg_.hidden) widths.push_back(h);
    widths.push_back(k);
    const std::size_t nl = widths.size() - 1;
    std::mt19937_64 rng(cfg_.seed);
    std::vector<Matrix> w(nl);
    std::vector<Vector> b(nl);
    for (std::size_t l = 0; l < nl; ++l) {
      const double lim = std::sqrt(6.0 / static_cast<double>(widths[l] + widths[l + 1]));
      std::uniform_real_distribution<double> u(-lim, lim);
      w[l] = Matrix::NullaryExpr(widths[l + 1], widths[l], [&] { return u(rng); });
      b[l] = Vector::Zero(widths[l + 1]);
    }
    Eigen::VectorXi target(n);
    for (Eigen::Index i = 0; i < n; ++i)
      target(i) = class_index(classes, d.y[static_cast<std::size_t>(i)]);
    // Optimiser state.
    std::vector<Matrix> mw(nl), vw(nl);
    std::vector<Vector> mb(nl), vb(nl);
    for (std::size_t l = 0; l < nl; ++l) {
      mw[l] = vw[l] = Matrix::Zero(w[l].rows(), w[l].cols());
      mb[l] = vb[l] = Vector::Zero(b[l].size());
    }
    std::vector<Eigen::Index> order(static_cast<std::size_t>(n));
    std::iota(order.begin(), order.end(), Eigen::Index{0});
    std::vector<Matrix> act(nl + 1);  // activations, one column per sample
    std::vector<Matrix> pre(nl);
    double best = std::numeric_limits<double>::infinity();
    int stale = 0;
    long long step = 0;
    epochs_ = 0;
    for (int epoch = 0; epoch < cfg_.epochs; ++epoch) {
      std::shuffle(order.begin(), order.end(), rng);
      double loss = 0.0;
      for (Eigen::Index start = 0; start < n; start += cfg_.batch_size) {
        const Eigen::Index bs = std::min<Eigen::Index>(cfg_.batch_size, n - start);
        act[0].resize(widths[0], bs);
        for (Eigen::Index j = 0; j < bs; ++j)
          act[0].col(j) = d.x.row(order[static_cast<std::size_t>(start + j)]).transpose();
        for (std::size_t l = 0; l < nl; ++l) {
          pre[l] = (w[l] * act[l]).colwise() + b[l];
          act[l + 1] = l + 1 < nl ? activate(pre[l]) : softmax(pre[l]);
        }
        Matrix delta = act[nl];
        for (Eigen::Index j = 0; j < bs; ++j) {
          const Eigen::Index t = target(order[static_cast<std::size_t>(start + j)]);
          loss -= std::log(std::max(delta(t, j), 1e-300));
          delta(t, j) -= 1.0;
        }
        delta /= static_cast<double>(bs);
        ++step;
        for (std::size_t l = nl; l-- > 0;) {
          Matrix gw = delta * act[l].transpose() + cfg_.l2 * w[l];
          Vector gb = delta.rowwise().sum();
          if (l > 0)
            delta = (w[l].transpose() * delta).cwiseProduct(derivative(pre[l - 1], act[l]));
          update(w[l], gw, mw[l], vw[l], step);
          update(b[l], gb, mb[l], vb[l], step);
        }
      }
      loss /= static_cast<double>(n);
      ++epochs_;
      if (!std::isfinite(loss)) {
        return {Status::degenerate, "Mlp: the training loss diverged at epoch " +
                                        std::to_string(epoch + 1) +
                                        "; lower learning_rate or scale the features"};
      }
      if (loss < best - cfg_.tolerance) {
        best = loss;
        stale = 0;
      } else if (++stale >= cfg_.patience) {
        break;
      }
    }
    loss_ = best;
    classes_ = std::move(classes);
    w_ = std::move(w);
    b_ = std::move(b);
    return o;
  }

  /// Class probabilities.
  template <class D = void>
  void decision(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    detail::check_sample(x, dims(), "Mlp");
    Deferred<Eigen::MatrixXd, D> a = x;
    for (std::size_t l = 0; l < w_.size(); ++l) {
      const Deferred<Eigen::MatrixXd, D> z = (w_[l] * a).colwise() + b_[l];
      a = l + 1 < w_.size() ? activate(z) : softmax(z);
    }
    out = a.col(0);
  }
  /// The label of sample `x` (Classifier).
  template <class = void>
  [[nodiscard]] int predict(const SampleRef& x) const {
    Eigen::VectorXd p(static_cast<Eigen::Index>(classes_.size()));
    decision(x, p);
    Eigen::Index best = 0;
    p.maxCoeff(&best);
    return classes_[static_cast<std::size_t>(best)];
  }
  /// Labels in the model's order (Classifier); empty before fit.
  [[nodiscard]] std::span<const int> classes() const noexcept { return classes_; }
  /// Number of features a sample has; 0 before fit (Classifier).
  [[nodiscard]] Eigen::Index dims() const noexcept { return w_.empty() ? 0 : w_[0].cols(); }
  /// Epochs run by the last fit.
  [[nodiscard]] int epochs() const noexcept { return epochs_; }
  /// Best mean training cross-entropy of the last fit.
  [[nodiscard]] double loss() const noexcept { return loss_; }

  /// Visits the options and the weights (encode_model / decode_model in model_file.hpp).
  template <class Ar>
  void state(Ar& ar) {
    ar.vector(cfg_.hidden, "hidden");
    ar.enumeration(cfg_.activation, 2, "activation");
    ar.enumeration(cfg_.optimizer, 2, "optimizer");
    ar.value(cfg_.learning_rate, "learning_rate");
    ar.value(cfg_.momentum, "momentum");
    ar.value(cfg_.l2, "l2");
    ar.value(cfg_.epochs, "epochs");
    ar.value(cfg_.batch_size, "batch_size");
    ar.value(cfg_.tolerance, "tolerance");
    ar.value(cfg_.patience, "patience");
    ar.value(cfg_.seed, "seed");
    ar.vector(classes_, "classes");
    ar.matrices(w_, "weights");
    ar.matrices(b_, "biases");
    ar.value(epochs_, "epochs run");
    ar.value(loss_, "loss");
    ar.verify([&]() -> std::string {
      (void)Mlp(cfg_);
      std::string e = detail::classes_error(classes_);
      if (!e.empty()) return e;
      if (w_.empty() && b_.empty()) return classes_.empty() ? "" : "classes without weights";
      if (w_.size() != cfg_.hidden.size() + 1 || b_.size() != w_.size())
        return "the layers disagree with hidden";
      for (std::size_t l = 0; l < w_.size(); ++l) {
        const Eigen::Index out =
            l + 1 < w_.size() ? cfg_.hidden[l] : static_cast<Eigen::Index>(classes_.size());
        if (w_[l].rows() != out || b_[l].size() != out || w_[l].cols() < 1 ||
            (l > 0 && w_[l].cols() != w_[l - 1].rows()))
          return "layer " + std::to_string(l) + "'s sizes disagree";
      }
      return {};
    });
  }

 private:
  template <class M>
  [[nodiscard]] M activate(const M& z) const {
    if (cfg_.activation == MlpActivation::tanh) return z.array().tanh().matrix();
    return z.cwiseMax(0.0);
  }
  // d act / d z, from the pre-activation z and activation a.
  template <class M>
  [[nodiscard]] M derivative(const M& z, const M& a) const {
    if (cfg_.activation == MlpActivation::tanh) return (1.0 - a.array().square()).matrix();
    return (z.array() > 0.0).template cast<double>().matrix();
  }
  template <class M>
  static M softmax(const M& z) {
    M e = (z.rowwise() - z.colwise().maxCoeff()).array().exp().matrix();
    return e.array().rowwise() / e.colwise().sum().array();
  }
  template <class M>
  void update(M& p, const M& g, M& m, M& v, long long step) const {
    if (cfg_.optimizer == MlpOptimizer::sgd) {
      m = cfg_.momentum * m - cfg_.learning_rate * g;
      p += m;
      return;
    }
    constexpr double b1 = 0.9;
    constexpr double b2 = 0.999;
    m = b1 * m + (1.0 - b1) * g;
    v = b2 * v + (1.0 - b2) * g.cwiseProduct(g);
    const double c1 = 1.0 - std::pow(b1, static_cast<double>(step));
    const double c2 = 1.0 - std::pow(b2, static_cast<double>(step));
    p.array() -= cfg_.learning_rate * (m.array() / c1) / ((v.array() / c2).sqrt() + 1e-8);
  }

  MlpConfig cfg_;
  std::vector<int> classes_;
  std::vector<Eigen::MatrixXd> w_;
  std::vector<Eigen::VectorXd> b_;
  int epochs_ = 0;
  double loss_ = 0.0;
};

}  // namespace taxel::learn
