// SPDX-License-Identifier: MIT
// Linear SVM trained by dual coordinate descent (Hsieh et al. 2008), following LIBLINEAR 2.3
// (`-s 1` L2-loss and `-s 3` L1-loss SVC): the same dual, stopping rule, shrinking, bias
// handling, one-vs-rest scheme, label order and model file, on dense row-major features.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/error.hpp"
#include "taxel/core/parallel.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// Loss of the linear SVM.
enum class SvmLoss {
  l2,  ///< squared hinge loss: LIBLINEAR -s 1 (L2R_L2LOSS_SVC_DUAL), the default
  l1,  ///< hinge loss: LIBLINEAR -s 3 (L2R_L1LOSS_SVC_DUAL)
};

/// Options of LinearSvm. The defaults are LIBLINEAR's (`train` with no options).
struct LinearSvmConfig {
  SvmLoss loss = SvmLoss::l2;  ///< -s 1 or -s 3
  double C = 1.0;              ///< -c: cost of constraint violation, > 0
  double eps = 0.1;            ///< -e: stop when max - min projected gradient <= eps, > 0
  double bias = -1.0;          ///< -B: < 0 for none; >= 0 appends this constant feature
  int max_iterations = 1000;   ///< outer iterations per binary problem (LIBLINEAR 2.3: 1000)
  bool shrinking = true;       ///< skip variables at a bound whose gradient points outward
  /// Seed of the per-iteration random permutation. Each binary problem of one-vs-rest draws
  /// from its own generator (the first, and the only one of two classes, from `seed` itself),
  /// so the model does not depend on `threads`.
  std::uint64_t seed = 1;
  bool record_objective = false;  ///< keep the dual objective after every outer iteration
  /// -w<label> weight: the cost of a class is weight * C (LIBLINEAR's weighted C: in
  /// one-vs-rest the class's own samples cost weight_k * C and the rest C; with two classes
  /// each class costs its own weight * C). Classes not listed weigh 1. Weights > 0.
  std::vector<std::pair<int, double>> class_weights{};
  /// Binary problems of one-vs-rest trained at once, each on its own thread (0: every core;
  /// more threads than classes are not started). The model is the same for any value.
  unsigned threads = 0;
};

/// What training did, per binary problem (one per class in one-vs-rest, one for two classes).
struct LinearSvmTrainInfo {
  std::vector<int> iterations;             ///< outer iterations
  std::vector<double> objective;           ///< final dual objective, as LIBLINEAR prints it
  std::vector<int> support_vectors;        ///< samples with alpha > 0
  std::vector<std::vector<double>> trace;  ///< dual objective per iteration (if recorded)
};

/// A linear SVM classifier: `decision_k(x) = w_k'x + b_k`, label = argmax (one-vs-rest), or
/// the sign of the single decision value for two classes. Models the Classifier concept.
/// Thread-safety: a trained model's const members (predict, decision, save) may run on
/// several threads at once; `fit` and `load` must not overlap with any other call.
class LinearSvm {
 public:
  /// Throws std::invalid_argument for C or eps not positive and finite, a non-finite bias or
  /// max_iterations < 1.
  explicit LinearSvm(LinearSvmConfig cfg = {}) : cfg_(cfg) {
    const auto bad = [](const char* field, double v, const char* range) {
      throw std::invalid_argument(std::string("LinearSvmConfig: ") + field + " = " +
                                  std::to_string(v) + " is outside the allowed range " + range);
    };
    if (!(cfg.C > 0.0) || !std::isfinite(cfg.C)) bad("C", cfg.C, "(0, inf)");
    if (!(cfg.eps > 0.0) || !std::isfinite(cfg.eps)) bad("eps", cfg.eps, "(0, inf)");
    if (!std::isfinite(cfg.bias)) bad("bias", cfg.bias, "(-inf, inf)");
    if (cfg.max_iterations < 1) bad("max_iterations", cfg.max_iterations, "[1, inf)");
    for (const auto& [label, weight] : cfg.class_weights) {
      if (!(weight > 0.0) || !std::isfinite(weight) || !std::isfinite(weight * cfg.C)) {
        throw std::invalid_argument("LinearSvmConfig: the weight of class " +
                                    std::to_string(label) + " = " + std::to_string(weight) +
                                    " is outside the allowed range (0, inf)");
      }
    }
  }

  /// Trains on `d`. Returns `invalid_input` (keeping the previous model) for an empty set,
  /// non-finite features, mismatched sizes or fewer than two classes; `not_converged` when a
  /// binary problem stopped at max_iterations (the model is the last iterate and usable).
  template <class D = void>
  Outcome fit(const Deferred<DatasetView, D>& d) {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    Outcome check = validate_training_set(d, "LinearSvm");
    if (!check) return check;
    std::vector<int> classes = class_order(d.y);
    const Eigen::Index n = d.rows();
    const Eigen::Index dims = d.dims();
    const int nr_class = static_cast<int>(classes.size());
    const int nr_w = nr_class == 2 ? 1 : nr_class;

    VectorXd qd_base(n);  // ||x_i||^2 + bias^2
    const double b2 = cfg_.bias >= 0.0 ? cfg_.bias * cfg_.bias : 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      qd_base(i) = d.x.row(i).squaredNorm() + b2;
      // An overflowing ||x||^2 would make every dual step 0 and return an all-zero model.
      if (!std::isfinite(qd_base(i))) {
        return {Status::invalid_input,
                "LinearSvm: the squared norm of sample " + std::to_string(i) +
                    " (with the bias feature) overflows; scale the features (and -B) below 1e150"};
      }
    }

    FeatureMatrix w(nr_w, dims);
    VectorXd wb(nr_w);
    LinearSvmTrainInfo info;
    const auto problems = static_cast<std::size_t>(nr_w);
    info.iterations.resize(problems);
    info.objective.resize(problems);
    info.support_vectors.resize(problems);
    info.trace.resize(problems);
    // The binary problems are independent: each writes its own row and slots.
    parallel_for(problems, cfg_.threads, [&](std::size_t k) {
      std::vector<signed char> sign(static_cast<std::size_t>(n));
      for (Eigen::Index i = 0; i < n; ++i) {
        sign[static_cast<std::size_t>(i)] = d.y[static_cast<std::size_t>(i)] == classes[k] ? 1 : -1;
      }
      VectorXd wk = VectorXd::Zero(dims);
      double wbk = 0.0;
      // Problem k's generator: `seed` for the first, then seeds a golden-ratio step apart.
      std::mt19937_64 rng(cfg_.seed + 0x9e3779b97f4a7c15ULL * k);
      const double cp = cost_of(classes[k]);
      const double cn = nr_class == 2 ? cost_of(classes[1]) : cfg_.C;
      const Solve s = solve(d.x, sign, qd_base, cp, cn, wk, wbk, rng,
                            cfg_.record_objective ? &info.trace[k] : nullptr);
      w.row(static_cast<Eigen::Index>(k)) = wk.transpose();
      wb(static_cast<Eigen::Index>(k)) = wbk;
      info.iterations[k] = s.iterations;
      info.objective[k] = s.objective;
      info.support_vectors[k] = s.support_vectors;
    });
    Outcome out;
    for (std::size_t k = 0; k < problems; ++k) {
      if (info.iterations[k] >= cfg_.max_iterations) {
        out = Outcome{Status::not_converged,
                      "LinearSvm: the binary problem of class " + std::to_string(classes[k]) +
                          " reached max_iterations = " + std::to_string(cfg_.max_iterations) +
                          " before the projected gradient spread fell to eps; scale the "
                          "features or raise eps"};
        break;
      }
    }
    if (!w.allFinite() || !wb.allFinite()) {
      return {Status::invalid_input,
              "LinearSvm: the weights overflowed during training; scale the features or lower C"};
    }
    classes_ = std::move(classes);
    w_ = std::move(w);
    wb_ = std::move(wb);
    bias_ = cfg_.bias;
    info_ = std::move(info);
    solver_ = cfg_.loss == SvmLoss::l2 ? "L2R_L2LOSS_SVC_DUAL" : "L2R_L1LOSS_SVC_DUAL";
    multiclass_cs_ = false;
    return out;
  }

  /// Decision values, one per class in `classes()` order (for two classes: `f` and `-f`).
  /// Throws std::invalid_argument for a sample of the wrong length or non-finite features.
  template <class D = void>
  void decision(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    detail::check_sample_size(x, dims(), "LinearSvm");
    if (out.size() != static_cast<Eigen::Index>(classes_.size())) {
      throw std::invalid_argument("LinearSvm::decision: the output has " +
                                  std::to_string(out.size()) + " entries, the model has " +
                                  std::to_string(classes_.size()) + " classes");
    }
    if (nr_w() == 1) {
      const double f = raw_value(x, 0);
      out(0) = f;
      out(1) = -f;
    } else {
      out.noalias() = w_ * x;
      if (bias_ >= 0.0) out += bias_ * wb_;
    }
    if (!out.allFinite()) non_finite(x);
  }

  /// The predicted label. Throws like decision(). Allocates nothing.
  template <class D = void>
  [[nodiscard]] int predict(const Deferred<SampleRef, D>& x) const {
    detail::check_sample_size(x, dims(), "LinearSvm");
    // A non-finite feature makes some decision value non-finite (0 * inf is NaN too), so the
    // scores are checked instead of the sample.
    if (nr_w() == 1) {
      const double f = raw_value(x, 0);
      if (!std::isfinite(f)) non_finite(x);
      return f > 0.0 ? classes_[0] : classes_[1];
    }
    Eigen::Index best = 0;
    if (nr_w() <= kStackClasses && dims() >= 32) {  // GEMV pays off beyond ~32 features
      Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kStackClasses, 1> v(nr_w());
      v.noalias() = w_ * x;
      if (bias_ >= 0.0) v += bias_ * wb_;
      if (!v.allFinite()) non_finite(x);
      v.maxCoeff(&best);
    } else {
      double best_v = -std::numeric_limits<double>::infinity();
      for (Eigen::Index k = 0; k < nr_w(); ++k) {
        const double v = raw_value(x, k);
        if (!std::isfinite(v)) non_finite(x);
        if (v > best_v) {
          best_v = v;
          best = k;
        }
      }
    }
    return classes_[static_cast<std::size_t>(best)];
  }

  /// Labels, in the model's order (LIBLINEAR's: first appearance, +1 before -1).
  [[nodiscard]] std::span<const int> classes() const noexcept { return classes_; }
  /// Features per sample (without the bias feature); 0 before training.
  [[nodiscard]] Eigen::Index dims() const noexcept { return w_.cols(); }
  /// Weight vectors, one row per binary problem (1 row for two classes).
  [[nodiscard]] const FeatureMatrix& weights() const noexcept { return w_; }
  /// Threads `fit` may train on (LinearSvmConfig::threads; the ThreadedTraining concept).
  [[nodiscard]] unsigned threads() const noexcept { return cfg_.threads; }
  /// Changes them for the next `fit`; the model does not depend on the count.
  void set_threads(unsigned threads) noexcept { cfg_.threads = threads; }
  /// Weight of the bias feature per binary problem; the intercept is `bias() * bias_weights()`.
  [[nodiscard]] const Eigen::VectorXd& bias_weights() const noexcept { return wb_; }
  /// The bias feature value (< 0: none).
  [[nodiscard]] double bias() const noexcept { return bias_; }
  /// The options.
  [[nodiscard]] const LinearSvmConfig& config() const noexcept { return cfg_; }
  /// Iterations, objectives and support vectors of the last fit.
  [[nodiscard]] const LinearSvmTrainInfo& info() const noexcept { return info_; }
  /// LIBLINEAR's name of the solver that produced the model.
  [[nodiscard]] const std::string& solver_type() const noexcept { return solver_; }

  /// The model as LIBLINEAR's text model file (readable by LIBLINEAR's `predict` and
  /// `load_model`): header lines `solver_type`, `nr_class`, `label`, `nr_feature`, `bias`, then
  /// `w` and one line per feature (plus one for the bias feature) holding one weight per binary
  /// problem. Numbers are written to round-trip exactly.
  template <class = void>
  [[nodiscard]] std::string save() const {
    if (dims() == 0) throw std::logic_error("LinearSvm::save: the model is not trained");
    std::string s;
    s.append("solver_type ").append(solver_).append("\nnr_class ");
    s.append(std::to_string(classes_.size())).append("\nlabel");
    for (int c : classes_) s.append(" ").append(std::to_string(c));
    s.append("\nnr_feature ").append(std::to_string(dims())).append("\nbias ");
    append_number(s, bias_);
    s.append("\nw\n");
    const Eigen::Index rows = dims() + (bias_ >= 0.0 ? 1 : 0);
    for (Eigen::Index j = 0; j < rows; ++j) {
      for (Eigen::Index k = 0; k < nr_w(); ++k) {
        append_number(s, j < dims() ? w_(k, j) : wb_(k));
        s.append(" ");
      }
      s.append("\n");
    }
    return s;
  }

  /// Reads a LIBLINEAR model file's text (any of LIBLINEAR's classification solvers; the model
  /// then predicts as LIBLINEAR does). Throws taxel::IoError naming `source` and the line.
  template <class D = void>
  [[nodiscard]] static LinearSvm load(std::string_view text,
                                      const std::string& source = "<model>") {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    Tokens tok(text, source);
    LinearSvm m;
    int nr_class = -1;
    long long nr_feature = -1;
    bool have_bias = false;
    for (;;) {
      const std::string_view key = tok.next("a header keyword or `w`");
      if (key == "w") break;
      if (key == "solver_type") {
        const std::string_view name = tok.next("a solver name");
        static constexpr std::string_view kKnown[] = {
            "L2R_LR",   "L2R_L2LOSS_SVC_DUAL", "L2R_L2LOSS_SVC", "L2R_L1LOSS_SVC_DUAL",
            "MCSVM_CS", "L1R_L2LOSS_SVC",      "L1R_LR",         "L2R_LR_DUAL"};
        if (std::find(std::begin(kKnown), std::end(kKnown), name) == std::end(kKnown)) {
          tok.fail("solver_type `" + std::string(name) +
                   "` is not a LIBLINEAR classification solver");
        }
        m.solver_ = std::string(name);
        m.multiclass_cs_ = name == "MCSVM_CS";
      } else if (key == "nr_class") {
        nr_class = static_cast<int>(tok.integer("nr_class", 2, 1 << 20));
      } else if (key == "label") {
        if (nr_class < 0) tok.fail("`label` before `nr_class`");
        m.classes_.clear();
        for (int c = 0; c < nr_class; ++c) {
          m.classes_.push_back(static_cast<int>(tok.integer("a label", INT32_MIN, INT32_MAX)));
        }
      } else if (key == "nr_feature") {
        nr_feature = tok.integer("nr_feature", 1, 1LL << 30);
      } else if (key == "bias") {
        m.bias_ = tok.real("bias");
        have_bias = true;
      } else {
        tok.fail("unknown header keyword `" + std::string(key) + "`");
      }
    }
    if (m.solver_.empty()) tok.fail("missing `solver_type`");
    if (nr_class < 0 || m.classes_.size() != static_cast<std::size_t>(nr_class)) {
      tok.fail("missing `nr_class` or `label`");
    }
    if (nr_feature < 0 || !have_bias) tok.fail("missing `nr_feature` or `bias`");
    for (std::size_t a = 0; a < m.classes_.size(); ++a) {
      for (std::size_t b = a + 1; b < m.classes_.size(); ++b) {
        if (m.classes_[a] == m.classes_[b])
          tok.fail("label " + std::to_string(m.classes_[a]) + " appears twice");
      }
    }
    const int nr_w = (nr_class == 2 && !m.multiclass_cs_) ? 1 : nr_class;
    const auto dims = static_cast<Eigen::Index>(nr_feature);
    // Read the weights before sizing anything, so that a header cannot make us allocate more
    // than the text holds.
    const Eigen::Index rows = dims + (m.bias_ >= 0.0 ? 1 : 0);
    std::vector<double> values;
    while (!tok.at_end()) {
      if (static_cast<double>(values.size()) >= static_cast<double>(rows) * nr_w) {
        tok.fail("unexpected text after the last weight");
      }
      values.push_back(tok.real("a weight"));
    }
    if (static_cast<double>(values.size()) < static_cast<double>(rows) * nr_w) {
      tok.fail("unexpected end of file; expected " + std::to_string(rows * nr_w) +
               " weights, found " + std::to_string(values.size()));
    }
    m.w_.resize(nr_w, dims);
    m.wb_ = VectorXd::Zero(nr_w);
    for (Eigen::Index j = 0; j < rows; ++j) {
      for (Eigen::Index k = 0; k < nr_w; ++k) {
        const double v = values[static_cast<std::size_t>(j * nr_w + k)];
        (j < dims ? m.w_(k, j) : m.wb_(k)) = v;
      }
    }
    return m;
  }

  /// Visits the options, the weights and the training record (encode_model / decode_model in
  /// model_file.hpp).
  template <class Ar>
  void state(Ar& ar) {
    ar.enumeration(cfg_.loss, 2, "loss");
    ar.value(cfg_.C, "C");
    ar.value(cfg_.eps, "eps");
    ar.value(cfg_.bias, "bias");
    ar.value(cfg_.max_iterations, "max_iterations");
    ar.value(cfg_.shrinking, "shrinking");
    ar.value(cfg_.seed, "seed");
    ar.value(cfg_.record_objective, "record_objective");
    ar.pairs(cfg_.class_weights, "class_weights");
    ar.value(cfg_.threads, "threads");
    ar.vector(classes_, "classes");
    ar.matrix(w_, "weights");
    ar.matrix(wb_, "bias weights");
    ar.value(bias_, "fitted bias");
    ar.vector(info_.iterations, "iterations");
    ar.vector(info_.objective, "objective");
    ar.vector(info_.support_vectors, "support vectors");
    ar.nested(info_.trace, "objective trace");
    ar.text(solver_, "solver");
    ar.value(multiclass_cs_, "multiclass_cs");
    ar.verify([&]() -> std::string {
      (void)LinearSvm(cfg_);
      std::string e = detail::classes_error(classes_);
      if (!e.empty()) return e;
      static constexpr std::string_view kKnown[] = {
          "L2R_LR",   "L2R_L2LOSS_SVC_DUAL", "L2R_L2LOSS_SVC", "L2R_L1LOSS_SVC_DUAL",
          "MCSVM_CS", "L1R_L2LOSS_SVC",      "L1R_LR",         "L2R_LR_DUAL"};
      if (std::find(std::begin(kKnown), std::end(kKnown), solver_) == std::end(kKnown))
        return "unknown solver " + solver_;
      const std::size_t k = classes_.size();
      if (k == 0) return w_.size() + wb_.size() == 0 ? "" : "weights without classes";
      const auto nr = static_cast<Eigen::Index>(k == 2 && !multiclass_cs_ ? 1 : k);
      if (k < 2 || w_.rows() != nr || wb_.size() != nr || w_.cols() < 1)
        return "classes and weights disagree";
      return {};
    });
  }

 private:
  struct Solve {
    int iterations = 0;
    double objective = 0.0;
    int support_vectors = 0;
  };

  static constexpr int kStackClasses = 32;

  [[nodiscard]] Eigen::Index nr_w() const noexcept { return w_.rows(); }

  [[noreturn]] static void non_finite(const SampleRef& x) {
    if (!x.allFinite())
      throw std::invalid_argument("LinearSvm: the sample has a non-finite feature");
    throw std::invalid_argument("LinearSvm: a decision value overflowed (features too large)");
  }

  template <class D = void>
  [[nodiscard]] double raw_value(const Deferred<SampleRef, D>& x, Eigen::Index k) const noexcept {
    double v = w_.row(k).dot(x.transpose());
    if (bias_ >= 0.0) v += bias_ * wb_(k);
    return v;
  }

  // The cost C of a class's samples: C times its weight.
  [[nodiscard]] double cost_of(int label) const noexcept {
    for (const auto& [l, weight] : cfg_.class_weights) {
      if (l == label) return weight * cfg_.C;
    }
    return cfg_.C;
  }

  // Dual coordinate descent of LIBLINEAR's solve_l2r_l1l2_svc, on dense rows: cp is the cost of
  // the samples with y = +1, cn of those with y = -1.
  template <class D = void>
  Solve solve(const Deferred<Eigen::Ref<const FeatureMatrix>, D>& x,
              const Deferred<std::vector<signed char>, D>& y,
              const Deferred<Eigen::VectorXd, D>& qd_base, double cp, double cn, Eigen::VectorXd& w,
              double& wb, std::mt19937_64& rng, std::vector<double>* trace) const {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    const auto n = static_cast<std::size_t>(x.rows());
    const Eigen::Index dims = x.cols();
    const double bias = cfg_.bias;
    const bool has_bias = bias >= 0.0;
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const bool l2 = cfg_.loss == SvmLoss::l2;
    // Indexed by (y + 1) / 2: the negative class first.
    const double diag_of[2] = {l2 ? 0.5 / cn : 0.0, l2 ? 0.5 / cp : 0.0};
    const double upper_of[2] = {l2 ? kInf : cn, l2 ? kInf : cp};
    std::vector<double> diag_i(n);
    for (std::size_t i = 0; i < n; ++i) diag_i[i] = diag_of[y[i] > 0 ? 1 : 0];

    std::vector<double> alpha(n, 0.0);
    std::vector<double> qd(n);
    std::vector<std::size_t> index(n);
    for (std::size_t i = 0; i < n; ++i) {
      qd[i] = qd_base(static_cast<Eigen::Index>(i)) + diag_i[i];
      index[i] = i;
    }
    std::size_t active = n;
    double pg_max_old = kInf;
    double pg_min_old = -kInf;
    const double* base = x.data();
    const Eigen::Index stride = x.outerStride();
    int iter = 0;
    while (iter < cfg_.max_iterations) {
      double pg_max_new = -kInf;
      double pg_min_new = kInf;
      for (std::size_t i = 0; i < active; ++i) {
        const std::size_t j = i + static_cast<std::size_t>(rng() % (active - i));
        std::swap(index[i], index[j]);
      }
      for (std::size_t s = 0; s < active; ++s) {
        const std::size_t i = index[s];
        const double yi = y[i];
        const double diag = diag_i[i];
        const double upper = upper_of[yi > 0 ? 1 : 0];
        const Eigen::Map<const VectorXd> xi(base + static_cast<Eigen::Index>(i) * stride, dims);
        double g = xi.dot(w);
        if (has_bias) g += bias * wb;
        g = yi * g - 1.0 + alpha[i] * diag;
        double pg = 0.0;
        if (alpha[i] == 0.0) {
          if (cfg_.shrinking && g > pg_max_old) {
            --active;
            std::swap(index[s], index[active]);
            --s;
            continue;
          }
          if (g < 0.0) pg = g;
        } else if (alpha[i] == upper) {
          if (cfg_.shrinking && g < pg_min_old) {
            --active;
            std::swap(index[s], index[active]);
            --s;
            continue;
          }
          if (g > 0.0) pg = g;
        } else {
          pg = g;
        }
        pg_max_new = std::max(pg_max_new, pg);
        pg_min_new = std::min(pg_min_new, pg);
        if (std::fabs(pg) > 1.0e-12) {
          const double old = alpha[i];
          alpha[i] = std::min(std::max(old - g / qd[i], 0.0), upper);
          const double step = (alpha[i] - old) * yi;
          w.noalias() += step * xi;
          if (has_bias) wb += step * bias;
        }
      }
      ++iter;
      if (trace != nullptr) trace->push_back(dual_objective(w, wb, alpha, diag_i));
      if (pg_max_new - pg_min_new <= cfg_.eps) {
        if (active == n) break;
        active = n;  // converged on the shrunk set: check all variables once more
        pg_max_old = kInf;
        pg_min_old = -kInf;
        continue;
      }
      pg_max_old = pg_max_new;
      pg_min_old = pg_min_new;
      if (pg_max_old <= 0.0) pg_max_old = kInf;
      if (pg_min_old >= 0.0) pg_min_old = -kInf;
    }
    Solve s;
    s.iterations = iter;
    s.objective = dual_objective(w, wb, alpha, diag_i);
    for (double a : alpha) s.support_vectors += a > 0.0 ? 1 : 0;
    return s;
  }

  // 1/2 a'(Q + D)a - e'a = 1/2 (|w|^2 + sum a_i^2 D_ii) - sum a_i.
  template <class D = void>
  static double dual_objective(const Deferred<Eigen::VectorXd, D>& w, double wb,
                               const Deferred<std::vector<double>, D>& alpha,
                               const std::vector<double>& diag) {
    double v = w.squaredNorm() + wb * wb;
    for (std::size_t i = 0; i < alpha.size(); ++i) v += alpha[i] * (alpha[i] * diag[i] - 2.0);
    return 0.5 * v;
  }

  static void append_number(std::string& s, double v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    s.append(buf, r.ptr);
  }

  // Whitespace-separated tokens with line numbers, for the strict model reader.
  class Tokens {
   public:
    Tokens(std::string_view text, const std::string& source) : text_(text), source_(source) {}
    [[noreturn]] void fail(const std::string& why) const { throw IoError(source_, why, line_); }
    bool at_end() {
      skip();
      return pos_ >= text_.size();
    }
    std::string_view next(const char* what) {
      if (at_end()) fail(std::string("unexpected end of file; expected ") + what);
      const std::size_t start = pos_;
      while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
      return text_.substr(start, pos_ - start);
    }
    long long integer(const char* what, long long lo, long long hi) {
      const std::string_view t = next(what);
      long long v = 0;
      const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
      if (r.ec != std::errc{} || r.ptr != t.data() + t.size() || v < lo || v > hi) {
        fail(std::string("expected ") + what + " (an integer in [" + std::to_string(lo) + ", " +
             std::to_string(hi) + "]), found `" + std::string(t) + "`");
      }
      return v;
    }
    double real(const char* what) {
      const std::string_view t = next(what);
      double v = 0.0;
      const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
      if (r.ec != std::errc{} || r.ptr != t.data() + t.size() || !std::isfinite(v)) {
        fail(std::string("expected ") + what + " (a finite number), found `" + std::string(t) +
             "`");
      }
      return v;
    }

   private:
    static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }
    void skip() {
      while (pos_ < text_.size() && is_space(text_[pos_])) {
        if (text_[pos_] == '\n') ++line_;
        ++pos_;
      }
    }
    std::string_view text_;
    const std::string& source_;
    std::size_t pos_ = 0;
    std::uint64_t line_ = 1;
  };

  LinearSvmConfig cfg_;
  std::vector<int> classes_;
  FeatureMatrix w_;
  Eigen::VectorXd wb_;
  double bias_ = -1.0;
  LinearSvmTrainInfo info_;
  std::string solver_ = "L2R_L2LOSS_SVC_DUAL";
  bool multiclass_cs_ = false;
};

}  // namespace taxel::learn
