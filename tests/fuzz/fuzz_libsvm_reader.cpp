// SPDX-License-Identifier: MIT
// Fuzzes the libsvm data reader and the LIBLINEAR model reader with arbitrary bytes (the first
// byte picks one). A reader must throw taxel::IoError or return a consistent, finite result; a
// data set that reads is trained on and predicted, and a model that reads predicts. The
// learners' options come from the input's last four bytes, over the ranges they accept:
// LinearSvm's loss, C (1e-12 - 1e12), eps (1e-12 - 1e3), bias (none or 1e-6 - 1e6) and
// shrinking; on small data sets also Lda (shrinkage 0 - 1 or automatic), Knn (k 1 - 16, each
// metric and weighting), RbfSvm (C and gamma 1e-6 - 1e6) and Mlp (a few epochs of either
// optimiser and activation). A fit must return an outcome; a fitted model must predict one of
// the training labels.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <taxel/io/libsvm_format.hpp>
#include <taxel/learn.hpp>

#include "byte_range.hpp"

namespace {

// A fitted model's prediction of the first sample must be one of the training labels.
template <class Model>
void check_fitted(const Model& m, const taxel::learn::Dataset& d) {
  const int label = m.predict(d.x.row(0).transpose());
  if (std::find(d.y.begin(), d.y.end(), label) == d.y.end()) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int which = data[0] % 3;
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if (which == 2) bytes = "solver_type L2R_L2LOSS_SVC_DUAL\nnr_class " + bytes;
  try {
    if (which < 2) {
      const taxel::learn::Dataset d =
          taxel::io::parse_libsvm(bytes, "<fuzz>", {.dims = 0, .max_values = 1 << 16});
      if (d.rows() < 1 || d.dims() < 1 || d.y.size() != static_cast<std::size_t>(d.rows()) ||
          !d.x.allFinite() || (!d.groups.empty() && d.groups.size() != d.y.size())) {
        std::abort();
      }
      namespace tl = taxel::learn;
      using taxel::fuzz::log_range;
      const std::uint8_t* b = data + (size >= 5 ? size - 4 : 0);  // the options' four bytes
      tl::LinearSvmConfig lc{.max_iterations = 20};
      if (size >= 5) {
        lc.loss = b[0] & 1 ? tl::SvmLoss::l1 : tl::SvmLoss::l2;
        lc.shrinking = (b[0] & 2) != 0;
        lc.C = log_range(b[1], 1e-12, 1e12);
        lc.eps = log_range(b[2], 1e-12, 1e3);
        lc.bias = b[0] & 4 ? log_range(b[3], 1e-6, 1e6) : -1.0;
      }
      tl::LinearSvm m(lc);
      const taxel::Outcome o = m.fit(d.view());
      if (o.ok() || o.status == taxel::Status::not_converged) {
        if (!m.weights().allFinite()) std::abort();
        check_fitted(m, d);
        (void)taxel::io::parse_libsvm(taxel::io::encode_libsvm(d.view()));
      }
      if (size >= 5 && d.rows() <= 64 && d.dims() <= 64) {
        tl::Lda lda(tl::LdaConfig{.shrinkage = b[3] & 1 ? -1.0 : (b[3] >> 1) / 127.0,
                                  .empirical_priors = (b[0] & 8) != 0});
        if (lda.fit(d.view()).ok()) check_fitted(lda, d);
        tl::Knn knn(tl::KnnConfig{
            .k = 1 + (b[1] & 15),
            .metric = static_cast<tl::KnnMetric>((b[1] >> 4) & 1),
            .weighting = b[0] & 16 ? tl::KnnWeighting::distance : tl::KnnWeighting::uniform});
        if (knn.fit(d.view()).ok()) check_fitted(knn, d);
        tl::RbfSvm rbf(tl::RbfSvmConfig{.C = log_range(b[2], 1e-6, 1e6),
                                        .gamma = log_range(b[3], 1e-6, 1e6),
                                        .max_iterations = 2000});
        const taxel::Outcome ro = rbf.fit(d.view());
        if (ro.ok() || ro.status == taxel::Status::not_converged) check_fitted(rbf, d);
        tl::MlpConfig mc;
        mc.hidden = {1 + (b[2] & 7)};
        mc.activation = b[0] & 32 ? tl::MlpActivation::relu : tl::MlpActivation::tanh;
        mc.optimizer = b[0] & 64 ? tl::MlpOptimizer::sgd : tl::MlpOptimizer::adam;
        mc.learning_rate = log_range(b[1], 1e-6, 1.0);
        mc.epochs = 3;
        mc.batch_size = 1 + (b[3] & 7);
        tl::Mlp mlp(mc);
        if (mlp.fit(d.view()).ok()) check_fitted(mlp, d);
      }
    } else {
      const taxel::learn::LinearSvm m = taxel::learn::LinearSvm::load(bytes);
      if (m.dims() > 0 && m.dims() < 100000) {
        (void)m.predict(Eigen::VectorXd::Zero(m.dims()));
      }
    }
  } catch (const taxel::IoError&) {
  }
  return 0;
}
