// SPDX-License-Identifier: MIT
// C-SVC with a Gaussian (RBF) kernel, trained by SMO with LIBSVM's second-order working-set
// selection (Fan, Chen and Lin 2005) and an LRU cache of kernel columns; one-vs-one voting for
// several classes, as LIBSVM 3.24 does (`svm-train -t 2 -h 0`).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/status.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::learn {

/// Options of RbfSvm. K(x, z) = exp(-gamma |x - z|^2).
struct RbfSvmConfig {
  double C = 1.0;                ///< -c: cost, > 0
  double gamma = 0.0;            ///< -g: > 0; 0 means 1 / (number of features), LIBSVM's default
  double eps = 1e-3;             ///< -e: stop when the maximal violating pair's gap <= eps
  double cache_mb = 100.0;       ///< kernel column cache per binary problem, MiB
  long long max_iterations = 0;  ///< 0: LIBSVM's max(10^7, 100 l)

  /// The paper's parametrisation: K = exp(-|x - z|^2 / (2 sigma^2)).
  static RbfSvmConfig from_sigma(double sigma, double C = 1.0) {
    if (!(sigma > 0.0) || !std::isfinite(sigma)) {
      throw std::invalid_argument("RbfSvmConfig::from_sigma: sigma = " + std::to_string(sigma) +
                                  " is outside the allowed range (0, inf)");
    }
    RbfSvmConfig c;
    c.C = C;
    c.gamma = 1.0 / (2.0 * sigma * sigma);
    return c;
  }
};

/// Kernel SVM classifier. Decision values are one-vs-one votes per class (ties go to the class
/// first in `classes()`), as LIBSVM predicts. `pair_decision` gives the raw values. Models
/// Classifier.
class RbfSvm {
 public:
  /// Throws std::invalid_argument for C, eps or cache_mb not positive, or gamma negative.
  explicit RbfSvm(RbfSvmConfig cfg = {}) : cfg_(cfg) {
    const auto bad = [](const char* f, double v, const char* range) {
      throw std::invalid_argument(std::string("RbfSvmConfig: ") + f + " = " + std::to_string(v) +
                                  " is outside the allowed range " + range);
    };
    if (!(cfg.C > 0.0) || !std::isfinite(cfg.C)) bad("C", cfg.C, "(0, inf)");
    if (!(cfg.gamma >= 0.0) || !std::isfinite(cfg.gamma)) bad("gamma", cfg.gamma, "[0, inf)");
    if (!(cfg.eps > 0.0) || !std::isfinite(cfg.eps)) bad("eps", cfg.eps, "(0, inf)");
    if (!(cfg.cache_mb > 0.0)) bad("cache_mb", cfg.cache_mb, "(0, inf)");
    if (cfg.max_iterations < 0)
      bad("max_iterations", static_cast<double>(cfg.max_iterations), "[0, inf)");
  }

  /// Trains on `d`; the outcome says ok, not_converged or why it could not (Classifier).
  template <class D = void>
  Outcome fit(const Deferred<DatasetView, D>& d) {
    Outcome o = validate_training_set(d, "RbfSvm");
    if (!o) return o;
    std::vector<int> classes = class_order(d.y);
    const std::size_t k = classes.size();
    const double gamma = cfg_.gamma > 0.0 ? cfg_.gamma : 1.0 / static_cast<double>(d.dims());
    std::vector<std::vector<std::size_t>> members(k);
    for (std::size_t i = 0; i < d.y.size(); ++i) {
      members[static_cast<std::size_t>(class_index(classes, d.y[i]))].push_back(i);
    }
    std::vector<double> coef_all(d.y.size() * (k - 1), 0.0);  // LIBSVM's sv_coef layout
    std::vector<double> rho;
    iterations_.clear();
    for (std::size_t a = 0; a < k; ++a) {
      for (std::size_t b = a + 1; b < k; ++b) {
        std::vector<std::size_t> idx = members[a];
        idx.insert(idx.end(), members[b].begin(), members[b].end());
        std::vector<double> y(idx.size(), -1.0);
        std::fill(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(members[a].size()), 1.0);
        Binary sol = solve(d, idx, y, gamma);
        iterations_.push_back(sol.iterations);
        if (sol.iterations >= sol.max_iterations && o.ok()) {
          o = {Status::not_converged, "RbfSvm: SMO reached its iteration limit for classes " +
                                          std::to_string(classes[a]) + " vs " +
                                          std::to_string(classes[b])};
        }
        rho.push_back(sol.rho);
        // Coefficient of sample i in the (a, b) problem goes to column b-1 (if i in a) or a.
        for (std::size_t t = 0; t < idx.size(); ++t) {
          const std::size_t col = t < members[a].size() ? b - 1 : a;
          coef_all[idx[t] * (k - 1) + col] = sol.alpha[t] * y[t];
        }
      }
    }
    // Keep the support vectors (non-zero in some problem).
    std::vector<std::size_t> sv;
    for (std::size_t i = 0; i < d.y.size(); ++i) {
      for (std::size_t c = 0; c + 1 < k; ++c) {
        if (coef_all[i * (k - 1) + c] != 0.0) {
          sv.push_back(i);
          break;
        }
      }
    }
    sv_.resize(static_cast<Eigen::Index>(sv.size()), d.dims());
    coef_.resize(static_cast<Eigen::Index>(sv.size()), static_cast<Eigen::Index>(k - 1));
    sv_class_.resize(sv.size());
    for (std::size_t s = 0; s < sv.size(); ++s) {
      sv_.row(static_cast<Eigen::Index>(s)) = d.x.row(static_cast<Eigen::Index>(sv[s]));
      for (std::size_t c = 0; c + 1 < k; ++c) {
        coef_(static_cast<Eigen::Index>(s), static_cast<Eigen::Index>(c)) =
            coef_all[sv[s] * (k - 1) + c];
      }
      sv_class_[s] = class_index(classes, d.y[sv[s]]);
    }
    sv_sq_ = sv_.rowwise().squaredNorm();
    classes_ = std::move(classes);
    rho_ = std::move(rho);
    gamma_ = gamma;
    return o;
  }

  /// Raw one-vs-one decision values, LIBSVM's order: (0,1), (0,2), ..., (1,2), ...; positive
  /// favours the first class of the pair.
  template <class D = void>
  void pair_decision(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    detail::check_sample(x, dims(), "RbfSvm");
    const std::size_t k = classes_.size();
    if (out.size() != static_cast<Eigen::Index>(k * (k - 1) / 2)) {
      throw std::invalid_argument("RbfSvm::pair_decision: the output needs k(k-1)/2 entries");
    }
    const VectorXd kv =
        (-gamma_ * ((sv_sq_.array() + x.squaredNorm()) - 2.0 * (sv_ * x).array()).max(0.0)).exp();
    std::size_t p = 0;
    for (std::size_t a = 0; a < k; ++a) {
      for (std::size_t b = a + 1; b < k; ++b) {
        double sum = 0.0;
        for (Eigen::Index s = 0; s < sv_.rows(); ++s) {
          const auto c = static_cast<std::size_t>(sv_class_[static_cast<std::size_t>(s)]);
          if (c == a)
            sum += coef_(s, static_cast<Eigen::Index>(b - 1)) * kv(s);
          else if (c == b)
            sum += coef_(s, static_cast<Eigen::Index>(a)) * kv(s);
        }
        out(static_cast<Eigen::Index>(p)) = sum - rho_[p];
        ++p;
      }
    }
  }

  /// Votes per class.
  template <class D = void>
  void decision(const Deferred<SampleRef, D>& x, Eigen::Ref<Eigen::VectorXd> out) const {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    const std::size_t k = classes_.size();
    VectorXd pairs(static_cast<Eigen::Index>(k * (k - 1) / 2));
    pair_decision(x, pairs);
    if (out.size() != static_cast<Eigen::Index>(k)) {
      throw std::invalid_argument("RbfSvm::decision: the output needs one entry per class");
    }
    out.setZero();
    std::size_t p = 0;
    for (std::size_t a = 0; a < k; ++a) {
      for (std::size_t b = a + 1; b < k; ++b, ++p) {
        out(static_cast<Eigen::Index>(pairs(static_cast<Eigen::Index>(p)) > 0.0 ? a : b)) += 1.0;
      }
    }
  }
  /// The label of sample `x` (Classifier).
  template <class D = void>
  [[nodiscard]] int predict(const Deferred<SampleRef, D>& x) const {
    using VectorXd = Deferred<Eigen::VectorXd, D>;
    VectorXd votes(static_cast<Eigen::Index>(classes_.size()));
    decision(x, votes);
    Eigen::Index best = 0;
    for (Eigen::Index c = 1; c < votes.size(); ++c) {
      if (votes(c) > votes(best)) best = c;
    }
    return classes_[static_cast<std::size_t>(best)];
  }
  /// Labels in the model's order (Classifier); empty before fit.
  [[nodiscard]] std::span<const int> classes() const noexcept { return classes_; }
  /// Number of features a sample has; 0 before fit (Classifier).
  [[nodiscard]] Eigen::Index dims() const noexcept { return sv_.cols(); }
  /// Support vectors (one row each), in training order.
  [[nodiscard]] const FeatureMatrix& support_vectors() const noexcept { return sv_; }
  /// The kernel width used.
  [[nodiscard]] double gamma() const noexcept { return gamma_; }
  /// Bias of each pair problem (LIBSVM's rho; the decision is sum - rho).
  [[nodiscard]] std::span<const double> rho() const noexcept { return rho_; }
  /// SMO iterations of each pair problem in the last fit.
  [[nodiscard]] std::span<const long long> iterations() const noexcept { return iterations_; }

  /// Visits the options and the support vectors (encode_model / decode_model in
  /// model_file.hpp).
  template <class Ar>
  void state(Ar& ar) {
    ar.value(cfg_.C, "C");
    ar.value(cfg_.gamma, "gamma");
    ar.value(cfg_.eps, "eps");
    ar.value(cfg_.cache_mb, "cache_mb");
    ar.value(cfg_.max_iterations, "max_iterations");
    ar.vector(classes_, "classes");
    ar.matrix(sv_, "support vectors");
    ar.matrix(coef_, "coefficients");
    ar.vector(sv_class_, "support vector classes");
    ar.vector(rho_, "rho");
    ar.vector(iterations_, "iterations");
    ar.value(gamma_, "fitted gamma");
    ar.verify([&]() -> std::string {
      (void)RbfSvm(cfg_);
      std::string e = detail::classes_error(classes_);
      if (!e.empty()) return e;
      const std::size_t k = classes_.size();
      if (k == 0) return sv_.size() + coef_.size() + rho_.size() == 0 ? "" : "no classes";
      if (k < 2 || !(gamma_ > 0.0)) return "a fitted model needs two classes and gamma > 0";
      if (coef_.rows() != sv_.rows() || coef_.cols() != static_cast<Eigen::Index>(k - 1) ||
          sv_class_.size() != static_cast<std::size_t>(sv_.rows()) ||
          rho_.size() != k * (k - 1) / 2)
        return "support vectors, coefficients and rho disagree";
      for (int c : sv_class_) {
        if (c < 0 || static_cast<std::size_t>(c) >= k)
          return "a support vector's class is out of range";
      }
      return {};
    });
    sv_sq_ = sv_.rowwise().squaredNorm();
  }

 private:
  struct Binary {
    std::vector<double> alpha;
    double rho = 0.0;
    long long iterations = 0;
    long long max_iterations = 0;
  };

  // Kernel columns Q_ij = y_i y_j K(x_i, x_j) with an LRU cache.
  class KernelCache {
   public:
    KernelCache(const DatasetView& d, const std::vector<std::size_t>& idx,
                const std::vector<double>& y, double gamma, double mb)
        : y_(y), gamma_(gamma), l_(idx.size()) {
      x_.resize(static_cast<Eigen::Index>(l_), d.dims());
      for (std::size_t t = 0; t < l_; ++t)
        x_.row(static_cast<Eigen::Index>(t)) = d.x.row(static_cast<Eigen::Index>(idx[t]));
      sq_ = x_.rowwise().squaredNorm();
      const double cols = mb * 1024.0 * 1024.0 / (8.0 * static_cast<double>(l_));
      capacity_ = static_cast<std::size_t>(std::clamp(cols, 2.0, static_cast<double>(l_)));
      slot_.assign(l_, -1);
    }
    const double* column(std::size_t i) {
      ++clock_;
      if (slot_[i] >= 0) {
        used_[static_cast<std::size_t>(slot_[i])] = clock_;
        return data_[static_cast<std::size_t>(slot_[i])].data();
      }
      std::size_t s = 0;
      if (data_.size() < capacity_) {
        s = data_.size();
        data_.emplace_back(l_);
        owner_.push_back(i);
        used_.push_back(clock_);
      } else {
        s = static_cast<std::size_t>(std::min_element(used_.begin(), used_.end()) - used_.begin());
        slot_[owner_[s]] = -1;
        owner_[s] = i;
        used_[s] = clock_;
      }
      slot_[i] = static_cast<long long>(s);
      Eigen::Map<Eigen::VectorXd> col(data_[s].data(), static_cast<Eigen::Index>(l_));
      col.noalias() = x_ * x_.row(static_cast<Eigen::Index>(i)).transpose();
      const double si = sq_(static_cast<Eigen::Index>(i));
      for (std::size_t j = 0; j < l_; ++j) {
        const double d2 = std::max(0.0, sq_(static_cast<Eigen::Index>(j)) + si - 2.0 * data_[s][j]);
        data_[s][j] = y_[i] * y_[j] * std::exp(-gamma_ * d2);
      }
      return data_[s].data();
    }

   private:
    const std::vector<double>& y_;
    double gamma_;
    std::size_t l_;
    FeatureMatrix x_;
    Eigen::VectorXd sq_;
    std::size_t capacity_ = 2;
    std::vector<std::vector<double>> data_;
    std::vector<std::size_t> owner_;
    std::vector<std::uint64_t> used_;
    std::vector<long long> slot_;
    std::uint64_t clock_ = 0;
  };

  Binary solve(const DatasetView& d, const std::vector<std::size_t>& idx,
               const std::vector<double>& y, double gamma) const {
    constexpr double kTau = 1e-12;
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const std::size_t l = idx.size();
    const double c = cfg_.C;
    KernelCache q(d, idx, y, gamma, cfg_.cache_mb);
    Binary out;
    out.alpha.assign(l, 0.0);
    std::vector<double>& alpha = out.alpha;
    std::vector<double> g(l, -1.0);
    const double qd = 1.0;  // K(x, x) = 1
    const auto upper = [&](std::size_t i) { return alpha[i] >= c; };
    const auto lower = [&](std::size_t i) { return alpha[i] <= 0.0; };
    out.max_iterations = cfg_.max_iterations > 0
                             ? cfg_.max_iterations
                             : std::max<long long>(10000000, 100 * static_cast<long long>(l));
    long long iter = 0;
    while (iter < out.max_iterations) {
      // Working set: i maximises -y_i g_i over I_up; j minimises the second-order gain.
      double gmax = -kInf;
      double gmax2 = -kInf;
      std::ptrdiff_t ii = -1;
      std::ptrdiff_t jj = -1;
      double obj_min = kInf;
      for (std::size_t t = 0; t < l; ++t) {
        if (y[t] > 0) {
          if (!upper(t) && -g[t] >= gmax) {
            gmax = -g[t];
            ii = static_cast<std::ptrdiff_t>(t);
          }
        } else if (!lower(t) && g[t] >= gmax) {
          gmax = g[t];
          ii = static_cast<std::ptrdiff_t>(t);
        }
      }
      const std::size_t i = ii >= 0 ? static_cast<std::size_t>(ii) : 0;
      const double* qi = ii >= 0 ? q.column(i) : nullptr;
      for (std::size_t t = 0; t < l && qi != nullptr; ++t) {
        if (y[t] > 0) {
          if (lower(t)) continue;
          const double diff = gmax + g[t];
          gmax2 = std::max(gmax2, g[t]);
          if (diff > 0) {
            const double quad = qd + qd - 2.0 * y[i] * qi[t];
            const double obj = -(diff * diff) / (quad > 0 ? quad : kTau);
            if (obj <= obj_min) {
              jj = static_cast<std::ptrdiff_t>(t);
              obj_min = obj;
            }
          }
        } else {
          if (upper(t)) continue;
          const double diff = gmax - g[t];
          gmax2 = std::max(gmax2, -g[t]);
          if (diff > 0) {
            const double quad = qd + qd + 2.0 * y[i] * qi[t];
            const double obj = -(diff * diff) / (quad > 0 ? quad : kTau);
            if (obj <= obj_min) {
              jj = static_cast<std::ptrdiff_t>(t);
              obj_min = obj;
            }
          }
        }
      }
      if (gmax + gmax2 < cfg_.eps || jj < 0) break;
      ++iter;
      const auto j = static_cast<std::size_t>(jj);
      qi = q.column(i);
      const double* qj = q.column(j);
      const double ai = alpha[i];
      const double aj = alpha[j];
      if (y[i] != y[j]) {
        double quad = qd + qd + 2.0 * qi[j];
        if (quad <= 0) quad = kTau;
        const double delta = (-g[i] - g[j]) / quad;
        const double diff = alpha[i] - alpha[j];
        alpha[i] += delta;
        alpha[j] += delta;
        if (diff > 0) {
          if (alpha[j] < 0) {
            alpha[j] = 0;
            alpha[i] = diff;
          }
        } else if (alpha[i] < 0) {
          alpha[i] = 0;
          alpha[j] = -diff;
        }
        if (diff > 0) {  // C_i == C_j
          if (alpha[i] > c) {
            alpha[i] = c;
            alpha[j] = c - diff;
          }
        } else if (alpha[j] > c) {
          alpha[j] = c;
          alpha[i] = c + diff;
        }
      } else {
        double quad = qd + qd - 2.0 * qi[j];
        if (quad <= 0) quad = kTau;
        const double delta = (g[i] - g[j]) / quad;
        const double sum = alpha[i] + alpha[j];
        alpha[i] -= delta;
        alpha[j] += delta;
        if (sum > c) {
          if (alpha[i] > c) {
            alpha[i] = c;
            alpha[j] = sum - c;
          }
        } else if (alpha[j] < 0) {
          alpha[j] = 0;
          alpha[i] = sum;
        }
        if (sum > c) {
          if (alpha[j] > c) {
            alpha[j] = c;
            alpha[i] = sum - c;
          }
        } else if (alpha[i] < 0) {
          alpha[i] = 0;
          alpha[j] = sum;
        }
      }
      const double dai = alpha[i] - ai;
      const double daj = alpha[j] - aj;
      for (std::size_t t = 0; t < l; ++t) g[t] += qi[t] * dai + qj[t] * daj;
    }
    out.iterations = iter;
    // rho: mean of y_i g_i over free variables, else the middle of the feasible interval.
    double ub = kInf;
    double lb = -kInf;
    double sum_free = 0.0;
    int nr_free = 0;
    for (std::size_t t = 0; t < l; ++t) {
      const double yg = y[t] * g[t];
      if (upper(t)) {
        if (y[t] < 0)
          ub = std::min(ub, yg);
        else
          lb = std::max(lb, yg);
      } else if (lower(t)) {
        if (y[t] > 0)
          ub = std::min(ub, yg);
        else
          lb = std::max(lb, yg);
      } else {
        ++nr_free;
        sum_free += yg;
      }
    }
    out.rho = nr_free > 0 ? sum_free / nr_free : 0.5 * (ub + lb);
    return out;
  }

  RbfSvmConfig cfg_;
  std::vector<int> classes_;
  FeatureMatrix sv_;
  Eigen::VectorXd sv_sq_;
  Eigen::MatrixXd coef_;
  std::vector<int> sv_class_;
  std::vector<double> rho_;
  std::vector<long long> iterations_;
  double gamma_ = 0.0;
};

}  // namespace taxel::learn
