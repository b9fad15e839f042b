// SPDX-License-Identifier: MIT
// LinearSvm against LIBLINEAR and RbfSvm against LIBSVM, linked in when Debian's
// liblinear-dev / libsvm-dev are installed; accuracy on heart_scale (liblinear-tools).
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <taxel/io/file.hpp>
#include <taxel/io/libsvm_format.hpp>
#include <taxel/learn.hpp>
#include <vector>

#include "learn/learn_support.hpp"

#ifdef TAXEL_TEST_HAVE_LIBLINEAR
#include <linear.h>
#endif
#ifdef TAXEL_TEST_HAVE_LIBSVM
#include <libsvm/svm.h>
#endif

using namespace taxel::learn;

namespace {

// Sparse rows in the layout both libraries read, with the optional bias feature appended.
template <class Node>
struct SparseRows {
  std::vector<std::vector<Node>> rows;
  std::vector<Node*> ptr;
  std::vector<double> y;
  SparseRows(const Dataset& d, double bias) {
    const auto n = static_cast<int>(d.dims());
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
      std::vector<Node> r;
      for (int j = 0; j < n; ++j) {
        if (d.x(i, j) != 0.0) r.push_back({j + 1, d.x(i, j)});
      }
      if (bias >= 0) r.push_back({n + 1, bias});
      r.push_back({-1, 0.0});
      rows.push_back(std::move(r));
      y.push_back(d.y[static_cast<std::size_t>(i)]);
    }
    for (auto& r : rows) ptr.push_back(r.data());
  }
};

std::vector<std::pair<std::string, Dataset>> data_sets() {
  std::vector<std::pair<std::string, Dataset>> sets;
#ifdef TAXEL_TEST_HEART_SCALE
  sets.emplace_back("heart_scale", taxel::io::read_libsvm(TAXEL_TEST_HEART_SCALE));
#endif
  sets.emplace_back("blobs 2x5 (+1/-1)", taxel_test::blobs(80, 2, 5, 3.0, 31, true));
  sets.emplace_back("blobs 4x7", taxel_test::blobs(60, 4, 7, 2.5, 32));
  sets.emplace_back("blobs 3x20", taxel_test::blobs(50, 3, 20, 3.0, 33));
  return sets;
}

}  // namespace

#ifdef TAXEL_TEST_HAVE_LIBLINEAR
TEST_CASE("LinearSvm agrees with LIBLINEAR on converged weights and predictions",
          "[learn][oracle]") {
  set_print_string_function([](const char*) {});
  for (const auto& [name, d] : data_sets()) {
    for (const SvmLoss loss : {SvmLoss::l2, SvmLoss::l1}) {
      for (const double bias : {-1.0, 1.0}) {
        for (const bool weighted : {false, true}) {
          // Dual CD converges slowly at large C and LIBLINEAR stops at 1000 iterations.
          const double C = weighted                                       ? 0.02
                           : name == "heart_scale" && loss == SvmLoss::l2 ? 1.0
                                                                          : 0.05;
          INFO(name << ", loss " << (loss == SvmLoss::l2 ? "L2" : "L1") << ", bias " << bias
                    << (weighted ? ", class weights 3 and 0.5" : ""));
          LinearSvmConfig cfg{.loss = loss, .C = C, .eps = 1e-9, .bias = bias};
          // -w: the first two labels in the data, weighted 3 and 0.5 (LIBLINEAR's weighted C).
          std::vector<int> weight_label;
          std::vector<double> weight_value;
          if (weighted) {
            const std::vector<int> order = class_order(d.y);
            weight_label = {order[0], order[1]};
            weight_value = {3.0, 0.5};
            cfg.class_weights = {{order[0], 3.0}, {order[1], 0.5}};
          }
          LinearSvm ours(cfg);
          REQUIRE(ours.fit(d.view()).ok());

          SparseRows<feature_node> rows(d, bias);
          problem prob{static_cast<int>(d.rows()), static_cast<int>(d.dims()) + (bias >= 0 ? 1 : 0),
                       rows.y.data(), rows.ptr.data(), bias};
          parameter par{};
          par.solver_type = loss == SvmLoss::l2 ? L2R_L2LOSS_SVC_DUAL : L2R_L1LOSS_SVC_DUAL;
          par.eps = 1e-9;
          par.C = C;
          par.nr_weight = static_cast<int>(weight_label.size());
          par.weight_label = weight_label.data();
          par.weight = weight_value.data();
          model* theirs = train(&prob, &par);
          REQUIRE(theirs != nullptr);
          REQUIRE(get_nr_class(theirs) == static_cast<int>(ours.classes().size()));
          for (int c = 0; c < get_nr_class(theirs); ++c)
            CHECK(theirs->label[c] == ours.classes()[static_cast<std::size_t>(c)]);
          const int nr_w = static_cast<int>(ours.weights().rows());
          double max_diff = 0.0;
          for (int j = 0; j < static_cast<int>(d.dims()); ++j) {
            for (int k = 0; k < nr_w; ++k) {
              max_diff =
                  std::max(max_diff, std::fabs(theirs->w[j * nr_w + k] - ours.weights()(k, j)));
            }
          }
          if (bias >= 0) {
            for (int k = 0; k < nr_w; ++k) {
              max_diff = std::max(
                  max_diff, std::fabs(theirs->w[d.dims() * nr_w + k] - ours.bias_weights()(k)));
            }
          }
          CHECK(max_diff < 1e-6);
          int disagree = 0;
          for (Eigen::Index i = 0; i < d.rows(); ++i) {
            const auto a =
                static_cast<int>(::predict(theirs, rows.ptr[static_cast<std::size_t>(i)]));
            disagree += a != ours.predict(d.x.row(i).transpose()) ? 1 : 0;
          }
          CHECK(disagree == 0);

          // Model files cross over both ways.
          const auto dir = std::filesystem::temp_directory_path();
          const std::string ours_file = (dir / "taxel_oracle_ours.model").string();
          const std::string theirs_file = (dir / "taxel_oracle_theirs.model").string();
          taxel::io::write_file(ours_file, ours.save());
          model* loaded = load_model(ours_file.c_str());
          REQUIRE(loaded != nullptr);
          REQUIRE(save_model(theirs_file.c_str(), theirs) == 0);
          const LinearSvm back = LinearSvm::load(taxel::io::read_file(theirs_file), theirs_file);
          for (Eigen::Index i = 0; i < d.rows(); ++i) {
            const auto* xi = rows.ptr[static_cast<std::size_t>(i)];
            CHECK(static_cast<int>(::predict(loaded, xi)) == ours.predict(d.x.row(i).transpose()));
            CHECK(back.predict(d.x.row(i).transpose()) == static_cast<int>(::predict(theirs, xi)));
          }
          free_and_destroy_model(&loaded);
          free_and_destroy_model(&theirs);
          std::filesystem::remove(ours_file);
          std::filesystem::remove(theirs_file);
        }
      }
    }
  }
}
#endif

#ifdef TAXEL_TEST_HAVE_LIBSVM
TEST_CASE("RbfSvm agrees with LIBSVM (-t 2 -h 0) on decision values", "[learn][oracle]") {
  svm_set_print_string_function([](const char*) {});
  for (const auto& [name, d] : data_sets()) {
    INFO(name);
    RbfSvm ours(RbfSvmConfig{.C = 2.0, .eps = 1e-7});
    REQUIRE(ours.fit(d.view()).ok());
    SparseRows<svm_node> rows(d, -1.0);
    svm_problem prob{static_cast<int>(d.rows()), rows.y.data(), rows.ptr.data()};
    svm_parameter par{};
    par.svm_type = C_SVC;
    par.kernel_type = RBF;
    par.gamma = 1.0 / static_cast<double>(d.dims());
    par.C = 2.0;
    par.eps = 1e-7;
    par.cache_size = 100;
    par.shrinking = 0;
    svm_model* theirs = svm_train(&prob, &par);
    REQUIRE(theirs != nullptr);
    const int k = svm_get_nr_class(theirs);
    REQUIRE(k == static_cast<int>(ours.classes().size()));
    CHECK(svm_get_nr_sv(theirs) == static_cast<int>(ours.support_vectors().rows()));
    std::vector<double> dv(static_cast<std::size_t>(k * (k - 1) / 2));
    Eigen::VectorXd pd(k * (k - 1) / 2);
    double max_diff = 0.0;
    for (Eigen::Index i = 0; i < d.rows(); ++i) {
      const double label =
          svm_predict_values(theirs, rows.ptr[static_cast<std::size_t>(i)], dv.data());
      ours.pair_decision(d.x.row(i).transpose(), pd);
      for (std::size_t q = 0; q < dv.size(); ++q)
        max_diff = std::max(max_diff, std::fabs(pd(static_cast<Eigen::Index>(q)) - dv[q]));
      CHECK(static_cast<int>(label) == ours.predict(d.x.row(i).transpose()));
    }
    CHECK(max_diff < 1e-5);  // LIBSVM caches its kernel in single precision
    svm_free_and_destroy_model(&theirs);
  }
}
#endif

#ifdef TAXEL_TEST_HEART_SCALE
TEST_CASE("Every classifier reaches the known accuracy on heart_scale", "[learn][public-data]") {
  const Dataset d = taxel::io::read_libsvm(TAXEL_TEST_HEART_SCALE);
  REQUIRE(d.rows() == 270);
  REQUIRE(d.dims() == 13);
  // LIBLINEAR's README reports 83.3 % 5-fold CV at the best C; LIBSVM's guide 83-84 % for RBF.
  const auto cv = [&](const auto& c) {
    return cross_validate(c, d.view(), CvOptions{.seed = 3}).accuracy;
  };
  CHECK(cv(LinearSvm{}) == Approx(0.83).margin(0.03));
  CHECK(cv(LinearSvm{LinearSvmConfig{.C = 0.000488281}}) == Approx(0.833).margin(0.03));
  CHECK(cv(RbfSvm{}) == Approx(0.83).margin(0.03));
  CHECK(cv(Lda{}) == Approx(0.83).margin(0.03));
  CHECK(cv(Knn{KnnConfig{.k = 7}}) > 0.78);
  CHECK(cv(Mlp{MlpConfig{.hidden = {8}, .l2 = 1e-2, .epochs = 50}}) > 0.75);
}
#endif
