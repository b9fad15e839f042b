// SPDX-License-Identifier: MIT
// Classifiers to bytes and back (learn/model_file.hpp): the same decisions to the bit, the same
// options, and every damaged form refused with an IoError.
#include <catch2/catch.hpp>
#include <taxel/learn/model_file.hpp>

#include "learn/learn_support.hpp"

namespace {

using namespace taxel;
using namespace taxel::learn;

// Decision values of every sample, row by row.
template <class C>
Eigen::MatrixXd decisions(const C& m, const Dataset& d) {
  Eigen::MatrixXd out(d.x.rows(), static_cast<Eigen::Index>(m.classes().size()));
  for (Eigen::Index i = 0; i < d.x.rows(); ++i) {
    Eigen::VectorXd row(out.cols());
    m.decision(Eigen::VectorXd(d.x.row(i).transpose()), row);
    out.row(i) = row.transpose();
  }
  return out;
}

template <class C>
void round_trip(C model, const Dataset& d) {
  // Unfitted: the options survive, and the copy fits to the same model.
  const std::string blank = encode_model(model);
  C again = decode_model<C>(blank);
  CHECK(encode_model(again) == blank);
  CHECK(again.dims() == 0);

  REQUIRE(model.fit(d.view()).status != Status::invalid_input);
  REQUIRE(again.fit(d.view()).status != Status::invalid_input);
  const std::string bytes = encode_model(model);
  CHECK(encode_model(again) == bytes);

  const C copy = decode_model<C>(bytes, "copy");
  CHECK(encode_model(copy) == bytes);
  CHECK(copy.dims() == model.dims());
  CHECK(std::vector<int>(copy.classes().begin(), copy.classes().end()) ==
        std::vector<int>(model.classes().begin(), model.classes().end()));
  // Bit for bit: the same arithmetic on the same numbers.
  CHECK((decisions(copy, d).array() == decisions(model, d).array()).all());
  for (Eigen::Index i = 0; i < d.x.rows(); ++i) {
    const Eigen::VectorXd x = d.x.row(i).transpose();
    CHECK(copy.predict(x) == model.predict(x));
  }
  CHECK(model_kind(bytes) == learn::detail::model_kind<C>());

  // Every prefix is refused (cut short), and so is one byte more.
  for (std::size_t n = 0; n < bytes.size(); ++n) {
    CHECK_THROWS_AS(decode_model<C>(std::string_view(bytes).substr(0, n)), IoError);
  }
  CHECK_THROWS_WITH(decode_model<C>(bytes + "x"), Catch::Contains("left over"));
  // Another version, another kind.
  std::string v2 = bytes;
  v2[6] = 2;
  CHECK_THROWS_WITH(decode_model<C>(v2), Catch::Contains("version 2"));
  if constexpr (!std::is_same_v<C, Knn>) {
    CHECK_THROWS_WITH(decode_model<Knn>(bytes), Catch::Contains("not a Knn"));
  }
  CHECK_THROWS_WITH(decode_model<C>("TXOCAL\0\1 and more"), Catch::Contains("not a taxel model"));
}

}  // namespace

TEST_CASE("model_file: every classifier round-trips, fitted or not", "[learn][model_file]") {
  const Dataset three = taxel_test::blobs(20, 3, 4, 4.0, 7);
  const Dataset two = taxel_test::blobs(20, 2, 3, 3.0, 8);
  SECTION("LinearSvm") {
    LinearSvmConfig c;
    c.bias = 1.0;
    c.record_objective = true;
    c.class_weights = {{2, 1.5}};
    round_trip(LinearSvm(c), three);
    round_trip(LinearSvm(c), two);
  }
  SECTION("Knn") {
    round_trip(Knn({.k = 3, .metric = KnnMetric::manhattan, .weighting = KnnWeighting::distance}),
               three);
  }
  SECTION("Lda") { round_trip(Lda({.shrinkage = -1.0, .empirical_priors = false}), three); }
  SECTION("RbfSvm") { round_trip(RbfSvm({.C = 2.0, .gamma = 0.3}), three); }
  SECTION("Mlp") {
    MlpConfig c;
    c.hidden = {6, 4};
    c.activation = MlpActivation::relu;
    c.epochs = 20;
    round_trip(Mlp(c), three);
  }
}

TEST_CASE("model_file: damaged state is refused, naming what is wrong", "[learn][model_file]") {
  const Dataset d = taxel_test::blobs(10, 3, 2, 4.0, 9);
  Knn knn({.k = 3});
  REQUIRE(knn.fit(d.view()).ok());
  std::string bytes = encode_model(knn);
  // Header 8 + 3 ("Knn"); k (int32) is next: k = 0 is outside KnnConfig's range.
  std::string bad = bytes;
  bad[11] = 0;
  CHECK_THROWS_WITH(decode_model<Knn>(bad), Catch::Contains("k = 0"));
  // The metric byte out of range.
  bad = bytes;
  bad[15] = 7;
  CHECK_THROWS_WITH(decode_model<Knn>(bad), Catch::Contains("unknown value 7"));
  // The classes' count made huge: refused before anything is allocated.
  bad = bytes;
  for (int i = 0; i < 8; ++i) bad[17 + i] = '\xff';
  CHECK_THROWS_WITH(decode_model<Knn>(bad), Catch::Contains("bytes left hold"));

  // A NaN weight in a linear model.
  LinearSvm svm;
  REQUIRE(svm.fit(d.view()).status != Status::invalid_input);
  bytes = encode_model(svm);
  const std::size_t w =
      bytes.find(std::string(reinterpret_cast<const char*>(&svm.weights()(0, 0)), sizeof(double)));
  REQUIRE(w != std::string::npos);
  bad = bytes;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  bad.replace(w, sizeof(double), reinterpret_cast<const char*>(&nan), sizeof(double));
  CHECK_THROWS_WITH(decode_model<LinearSvm>(bad), Catch::Contains("weights is not finite"));

  // Duplicate labels.
  Lda lda;
  REQUIRE(lda.fit(d.view()).ok());
  bytes = encode_model(lda);
  // shrinkage (8) + priors (1) after the 8 + 3 header, then the count and the labels 1, 2, 3.
  bad = bytes;
  bad[8 + 3 + 9 + 8 + 4] = 1;
  CHECK_THROWS_WITH(decode_model<Lda>(bad), Catch::Contains("label 1 twice"));
}
