// SPDX-License-Identifier: MIT
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <mutex>
#include <numbers>
#include <set>
#include <taxel/image/recognizer.hpp>
#include <taxel/io/libsvm_format.hpp>
#include <taxel/learn.hpp>

#include "learn/learn_support.hpp"

using namespace taxel::learn;
using Catch::Matchers::Contains;
using taxel::Outcome;
using taxel::Status;

static_assert(Classifier<LinearSvm>);
static_assert(Classifier<Lda>);
static_assert(Classifier<Knn>);
static_assert(Classifier<RbfSvm>);
static_assert(Classifier<Mlp>);
static_assert(Classifier<Scaled<StandardScaler, LinearSvm>>);
static_assert(Classifier<Scaled<RangeScaler, RbfSvm>>);
// A trained LinearSvm plugs into the pressure-image Recognizer as its feature classifier.
static_assert(taxel::image::FeatureClassifier<LinearSvm>);
static_assert(taxel::image::FeatureClassifier<Scaled<StandardScaler, LinearSvm>>);

namespace {

// Primal objective of the L2-regularised SVM: 1/2 |w|^2 + C sum loss(y w'x).
double primal(const LinearSvm& m, const Dataset& d, SvmLoss loss, double C) {
  REQUIRE(m.classes().size() == 2);
  const double wb = m.bias() >= 0 ? m.bias_weights()(0) : 0.0;
  double v = 0.5 * (m.weights().row(0).squaredNorm() + wb * wb);
  for (Eigen::Index i = 0; i < d.rows(); ++i) {
    const double y = d.y[static_cast<std::size_t>(i)] == m.classes()[0] ? 1.0 : -1.0;
    double f = m.weights().row(0).dot(d.x.row(i));
    if (m.bias() >= 0) f += m.bias() * wb;
    const double h = std::max(0.0, 1.0 - y * f);
    v += C * (loss == SvmLoss::l2 ? h * h : h);
  }
  return v;
}

double training_accuracy(const auto& model, const Dataset& d) {
  int right = 0;
  for (Eigen::Index i = 0; i < d.rows(); ++i) {
    right += model.predict(d.x.row(i).transpose()) == d.y[static_cast<std::size_t>(i)] ? 1 : 0;
  }
  return static_cast<double>(right) / static_cast<double>(d.rows());
}

}  // namespace

TEST_CASE("class_order is LIBLINEAR's: first appearance, +1 before -1 for a -1/+1 set", "[learn]") {
  const std::vector<int> a{3, 1, 3, 2, 1};
  CHECK(class_order(a) == std::vector<int>{3, 1, 2});
  const std::vector<int> b{-1, 1, 1, -1};
  CHECK(class_order(b) == std::vector<int>{1, -1});
  const std::vector<int> c{-1, 2};
  CHECK(class_order(c) == std::vector<int>{-1, 2});
}

TEST_CASE("LinearSvm closes the duality gap on both losses, with and without bias", "[learn]") {
  const Dataset d = taxel_test::blobs(60, 2, 5, 2.0, 7, true);
  for (const SvmLoss loss : {SvmLoss::l2, SvmLoss::l1}) {
    for (const double bias : {-1.0, 1.0}) {
      for (const double C : {0.1, 1.0}) {
        LinearSvmConfig cfg;
        cfg.loss = loss;
        cfg.bias = bias;
        cfg.C = C;
        cfg.eps = 1e-10;
        cfg.max_iterations = 100000;
        LinearSvm m(cfg);
        REQUIRE(m.fit(d.view()).ok());
        const double p = primal(m, d, loss, C);
        const double dual = -m.info().objective[0];  // the solver minimises the negated dual
        INFO("loss " << static_cast<int>(loss) << " bias " << bias << " C " << C);
        CHECK(p >= dual - 1e-9 * std::fabs(p));
        CHECK(p - dual <= 1e-7 * std::fabs(p));
      }
    }
  }
}

TEST_CASE("LinearSvm's dual objective decreases monotonically", "[learn]") {
  const Dataset d = taxel_test::blobs(100, 3, 8, 1.5, 11);
  for (const SvmLoss loss : {SvmLoss::l2, SvmLoss::l1}) {
    LinearSvmConfig cfg;
    cfg.loss = loss;
    cfg.eps = 1e-6;
    cfg.record_objective = true;
    LinearSvm m(cfg);
    REQUIRE(m.fit(d.view()).status != Status::invalid_input);
    REQUIRE(m.info().trace.size() == 3);
    for (const auto& trace : m.info().trace) {
      REQUIRE(trace.size() >= 2);
      for (std::size_t i = 1; i < trace.size(); ++i) {
        CHECK(trace[i] <= trace[i - 1] + 1e-12 * std::fabs(trace[i - 1]));
      }
      CHECK(trace.back() < 0.0);
    }
  }
}

TEST_CASE("LinearSvm: one-vs-rest on separable classes, seeded and deterministic", "[learn]") {
  const Dataset d = taxel_test::blobs(50, 4, 6, 12.0, 3);
  LinearSvm a;
  LinearSvm b;
  REQUIRE(a.fit(d.view()).ok());
  REQUIRE(b.fit(d.view()).ok());
  CHECK(a.weights() == b.weights());
  CHECK(a.weights().rows() == 4);
  CHECK(training_accuracy(a, d) == 1.0);
  CHECK(std::vector<int>(a.classes().begin(), a.classes().end()) == std::vector<int>{1, 2, 3, 4});
  Eigen::VectorXd dec(4);
  a.decision(d.x.row(0).transpose(), dec);
  Eigen::Index best = 0;
  dec.maxCoeff(&best);
  CHECK(a.classes()[static_cast<std::size_t>(best)] == a.predict(d.x.row(0).transpose()));
}

TEST_CASE("LinearSvm model text round-trips exactly and is strict", "[learn]") {
  const Dataset d = taxel_test::blobs(40, 3, 4, 3.0, 5);
  LinearSvmConfig cfg;
  cfg.bias = 1.0;
  LinearSvm m(cfg);
  REQUIRE(m.fit(d.view()).ok());
  const std::string text = m.save();
  CHECK_THAT(
      text,
      Contains(
          "solver_type L2R_L2LOSS_SVC_DUAL\nnr_class 3\nlabel 1 2 3\nnr_feature 4\nbias 1\nw\n"));
  const LinearSvm back = LinearSvm::load(text);
  CHECK(back.weights() == m.weights());
  CHECK(back.bias_weights() == m.bias_weights());
  CHECK(back.save() == text);

  const auto bad = [](const std::string& t, const std::string& what) {
    INFO(t);
    try {
      (void)LinearSvm::load(t, "m.model");
      FAIL("no error");
    } catch (const taxel::IoError& e) {
      CHECK_THAT(e.what(), Contains(what));
    }
  };
  const std::string head =
      "solver_type L2R_L2LOSS_SVC_DUAL\nnr_class 2\nlabel 1 -1\nnr_feature 2\nbias -1\nw\n";
  bad(head + "0.5\n", "m.model:8: unexpected end of file; expected 2 weights, found 1");
  bad(head + "0.5\nx\n", "m.model:8: expected a weight");
  bad(head + "0.5\nnan\n", "a finite number");
  bad(head + "0.5\n1\n2\n", "unexpected text after the last weight");
  bad("solver_type L2R_L2LOSS_SVR\n", "not a LIBLINEAR classification solver");
  bad("solver_type L2R_L2LOSS_SVC_DUAL\nnr_class 2\nlabel 1 1\nnr_feature 1\nbias -1\nw\n1\n",
      "appears twice");
  bad("solver_type L2R_L2LOSS_SVC_DUAL\nfoo 1\n", "m.model:2: unknown header keyword `foo`");
  bad("", "expected a header keyword");
}

TEST_CASE("Classifiers refuse bad training sets and bad samples with clear errors", "[learn]") {
  Dataset d = taxel_test::blobs(10, 2, 3, 3.0, 1);
  const auto check_all = [](const DatasetView& v, const std::string& what) {
    INFO(what);
    LinearSvm s;
    Outcome o = s.fit(v);
    CHECK(o.status == Status::invalid_input);
    CHECK_THAT(o.message, Contains(what));
    CHECK(Lda{}.fit(v).status == Status::invalid_input);
    CHECK(RbfSvm{}.fit(v).status == Status::invalid_input);
    CHECK(Mlp{}.fit(v).status == Status::invalid_input);
  };
  {
    Dataset one = d;
    std::fill(one.y.begin(), one.y.end(), 4);
    check_all(one.view(), "1 class; at least 2 are needed");
  }
  {
    Dataset nan = d;
    nan.x(3, 1) = std::nan("");
    check_all(nan.view(), "feature 2 of sample 4 is not finite");
  }
  {
    Dataset empty;
    empty.x.resize(0, 3);
    check_all(empty.view(), "empty");
  }
  {
    Dataset short_labels = d;
    short_labels.y.pop_back();
    check_all(short_labels.view(), "20 samples but 19 labels");
  }
  // A failed fit keeps the previous model.
  LinearSvm m;
  REQUIRE(m.fit(d.view()).ok());
  const FeatureMatrix w = m.weights();
  Dataset nan = d;
  nan.x(0, 0) = INFINITY;
  CHECK_FALSE(m.fit(nan.view()).ok());
  CHECK(m.weights() == w);

  const Eigen::VectorXd wrong = Eigen::VectorXd::Zero(4);
  CHECK_THROWS_WITH(m.predict(wrong),
                    Contains("the sample has 4 features, the model was trained on 3"));
  Eigen::VectorXd bad = Eigen::VectorXd::Zero(3);
  bad(1) = std::nan("");
  CHECK_THROWS_AS(m.predict(bad), std::invalid_argument);
  CHECK_THROWS_AS(LinearSvm{}.predict(bad), std::logic_error);
  CHECK_THROWS_AS(Knn{}.predict(bad), std::logic_error);
  CHECK_THROWS_WITH(LinearSvm(LinearSvmConfig{.C = 0.0}), Contains("C = 0"));
  CHECK_THROWS_WITH(LinearSvm(LinearSvmConfig{.eps = -1.0}), Contains("eps"));
  CHECK_THROWS_AS(Knn(KnnConfig{.k = 0}), std::invalid_argument);
  CHECK_THROWS_AS(RbfSvm(RbfSvmConfig{.C = -1.0}), std::invalid_argument);
  CHECK_THROWS_AS(RbfSvmConfig::from_sigma(0.0), std::invalid_argument);
  CHECK_THROWS_AS(Mlp(MlpConfig{.hidden = {4, 4, 4}}), std::invalid_argument);
  CHECK_THROWS_AS(Lda(LdaConfig{.shrinkage = 2.0}), std::invalid_argument);
  CHECK(Knn(KnnConfig{.k = 50}).fit(d.view()).status == Status::invalid_input);
}

TEST_CASE("Scalers fit on training data only", "[learn]") {
  FeatureMatrix train(4, 3);
  train << 1, 10, 5, 2, 20, 5, 3, 30, 5, 4, 40, 5;
  StandardScaler z;
  REQUIRE(z.fit(train).ok());
  FeatureMatrix t = train;
  z.transform_in_place(t);
  CHECK(t.colwise().mean().norm() == Approx(0.0).margin(1e-12));
  CHECK(t.col(0).squaredNorm() / 4.0 == Approx(1.0));
  CHECK(t.col(2).isZero());  // constant in training
  Eigen::VectorXd out(3);
  z.transform(Eigen::Vector3d(5.5, 0.0, 7.0), out);
  const double sd0 = std::sqrt(1.25);
  CHECK(out(0) == Approx((5.5 - 2.5) / sd0));
  CHECK(out(2) == 0.0);

  RangeScaler r;
  REQUIRE(r.fit(train).ok());
  t = train;
  r.transform_in_place(t);
  CHECK(t.col(0).minCoeff() == Approx(-1.0));
  CHECK(t.col(1).maxCoeff() == Approx(1.0));
  r.transform(Eigen::Vector3d(7.0, 25.0, 5.0), out);  // beyond the training range stays linear
  CHECK(out(0) == Approx(3.0));
  CHECK(out(1) == Approx(0.0));
  CHECK_THROWS_AS(RangeScaler(1.0, 1.0), std::invalid_argument);
  CHECK_THROWS_AS(r.transform(Eigen::Vector2d(1, 2), out), std::invalid_argument);
  FeatureMatrix nan = train;
  nan(0, 0) = NAN;
  CHECK(StandardScaler{}.fit(nan).status == Status::invalid_input);
}

TEST_CASE("Every competitor beats chance clearly on separable data", "[learn]") {
  const Dataset d = taxel_test::blobs(60, 4, 8, 6.0, 21);
  const auto cv = [&](const auto& c) {
    CvReport r = cross_validate(c, d.view());
    REQUIRE(r.status != Status::invalid_input);
    return r.accuracy;
  };
  CHECK(cv(LinearSvm{}) > 0.95);
  CHECK(cv(Lda{}) > 0.95);
  CHECK(cv(Lda{LdaConfig{.shrinkage = -1.0}}) > 0.95);
  CHECK(cv(Knn{}) > 0.95);
  CHECK(cv(RbfSvm{}) > 0.95);
  CHECK(cv(Scaled<StandardScaler, Mlp>{}) > 0.95);
  CHECK(cv(Scaled<StandardScaler, Mlp>{Mlp{MlpConfig{.hidden = {16, 8},
                                                     .activation = MlpActivation::relu,
                                                     .optimizer = MlpOptimizer::sgd}}}) > 0.95);
}

TEST_CASE("Kernel methods and the MLP learn XOR, which a linear model cannot", "[learn]") {
  const Dataset d = taxel_test::xor_set(400, 2, 9);
  const double linear = cross_validate(LinearSvm{}, d.view()).accuracy;
  CHECK(linear < 0.7);
  CHECK(cross_validate(RbfSvm{RbfSvmConfig{.C = 10.0, .gamma = 2.0}}, d.view()).accuracy > 0.95);
  CHECK(cross_validate(Knn{}, d.view()).accuracy > 0.9);
  CHECK(cross_validate(Mlp{MlpConfig{.hidden = {16}}}, d.view()).accuracy > 0.9);
  Mlp a;
  Mlp b;
  REQUIRE(a.fit(d.view()).ok());
  REQUIRE(b.fit(d.view()).ok());
  Eigen::VectorXd pa(2);
  Eigen::VectorXd pb(2);
  a.decision(d.x.row(5).transpose(), pa);
  b.decision(d.x.row(5).transpose(), pb);
  CHECK(pa == pb);
  CHECK(pa.sum() == Approx(1.0));
}

TEST_CASE("Lda with full shrinkage and uniform priors is the nearest-mean classifier", "[learn]") {
  const Dataset d = taxel_test::blobs(30, 3, 5, 2.0, 4);
  Lda lda(LdaConfig{.shrinkage = 1.0, .empirical_priors = false});
  REQUIRE(lda.fit(d.view()).ok());
  for (Eigen::Index i = 0; i < d.rows(); ++i) {
    Eigen::Index nearest = 0;
    (lda.means().rowwise() - d.x.row(i)).rowwise().squaredNorm().minCoeff(&nearest);
    CHECK(lda.predict(d.x.row(i).transpose()) == lda.classes()[static_cast<std::size_t>(nearest)]);
  }
  // Singular covariance (a constant feature) is handled by the pseudo-inverse.
  Dataset c = d;
  c.x.col(2).setConstant(3.0);
  REQUIRE(Lda{}.fit(c.view()).ok());
  CHECK(cross_validate(Lda{}, c.view()).accuracy > 0.7);
  CHECK(Lda{LdaConfig{.shrinkage = -1.0}}.fit(c.view()).ok());
}

TEST_CASE("Knn matches a sort of all distances", "[learn]") {
  const Dataset d = taxel_test::blobs(25, 3, 4, 1.0, 8);
  for (const KnnMetric metric : {KnnMetric::euclidean, KnnMetric::manhattan}) {
    Knn knn(KnnConfig{.k = 1, .metric = metric});
    REQUIRE(knn.fit(d.view()).ok());
    const Eigen::Vector4d q(0.3, -0.2, 0.1, 0.5);
    Eigen::Index best = 0;
    if (metric == KnnMetric::euclidean) {
      (d.x.rowwise() - q.transpose()).rowwise().squaredNorm().minCoeff(&best);
    } else {
      (d.x.rowwise() - q.transpose()).cwiseAbs().rowwise().sum().minCoeff(&best);
    }
    CHECK(knn.predict(q) == d.y[static_cast<std::size_t>(best)]);
    // Every training sample is its own nearest neighbour.
    CHECK(training_accuracy(knn, d) == 1.0);
  }
}

TEST_CASE("K-fold assignments are stratified, or keep groups together", "[learn]") {
  const Dataset d = taxel_test::blobs(23, 3, 2, 1.0, 2);
  auto f = kfold_assignment(d.y, 5, 42);
  REQUIRE(f.ok());
  for (int label = 1; label <= 3; ++label) {
    std::vector<int> per_fold(5, 0);
    for (std::size_t i = 0; i < d.y.size(); ++i) {
      if (d.y[i] == label) ++per_fold[static_cast<std::size_t>(f.value[i])];
    }
    CHECK(*std::max_element(per_fold.begin(), per_fold.end()) -
              *std::min_element(per_fold.begin(), per_fold.end()) <=
          1);
  }
  auto g = kfold_assignment(d.y, 5, 42, d.groups);
  REQUIRE(g.ok());
  for (std::size_t i = 0; i < d.y.size(); ++i) {
    for (std::size_t j = 0; j < d.y.size(); ++j) {
      if (d.groups[i] == d.groups[j]) CHECK(g.value[i] == g.value[j]);
    }
  }
  CHECK(std::set<int>(g.value.begin(), g.value.end()).size() == 5);
  CHECK(kfold_assignment(d.y, 1, 1).status == Status::invalid_input);
  CHECK(kfold_assignment(d.y, 1000, 1).status == Status::invalid_input);
  CHECK_THAT(kfold_assignment(d.y, 11, 1, d.groups).message, Contains("only 10 groups"));
}

TEST_CASE("cross_validate reports a consistent confusion matrix, noise hurts", "[learn]") {
  const Dataset d = taxel_test::blobs(40, 4, 6, 4.0, 13);
  const CvReport r = cross_validate(LinearSvm{}, d.view());
  REQUIRE(r.ok());
  CHECK(r.confusion.sum() == d.rows());
  CHECK(static_cast<double>(r.confusion.trace()) / static_cast<double>(d.rows()) ==
        Approx(r.accuracy));
  for (Eigen::Index c = 0; c < 4; ++c) {
    CHECK(r.per_class_accuracy(c) ==
          Approx(static_cast<double>(r.confusion(c, c)) / r.confusion.row(c).sum()));
  }
  const CvReport grouped = cross_validate(LinearSvm{}, d.view(), CvOptions{.grouped = true});
  REQUIRE(grouped.ok());
  CvOptions noisy;
  noisy.snr_db = -5.0;
  const CvReport n1 = cross_validate(LinearSvm{}, d.view(), noisy);
  noisy.noise_target = NoiseTarget::both;
  const CvReport n2 = cross_validate(LinearSvm{}, d.view(), noisy);
  CHECK(n1.accuracy < r.accuracy - 0.1);
  CHECK(n2.accuracy < r.accuracy - 0.1);
  // Progress comes from the folds' threads, one call at a time: record, then check here.
  std::vector<std::pair<std::size_t, std::size_t>> calls;
  (void)cross_validate(Knn{}, d.view(),
                       CvOptions{.folds = 3, .progress = [&](std::size_t done, std::size_t total) {
                                   calls.emplace_back(done, total);
                                 }});
  CHECK(calls == std::vector<std::pair<std::size_t, std::size_t>>{{1, 3}, {2, 3}, {3, 3}});
  Dataset no_groups = d;
  no_groups.groups.clear();
  CHECK(cross_validate(LinearSvm{}, no_groups.view(), CvOptions{.grouped = true}).status ==
        Status::invalid_input);
}

TEST_CASE("cross_validate and five_by_two_cv give the same results on any number of threads",
          "[learn][threads]") {
  const Dataset d = taxel_test::blobs(30, 3, 5, 2.0, 21);
  for (const double snr : {std::numeric_limits<double>::infinity(), 3.0}) {
    for (const NoiseTarget target : {NoiseTarget::test_only, NoiseTarget::both}) {
      CvOptions one{.folds = 5, .seed = 4, .snr_db = snr, .noise_target = target, .threads = 1};
      CvOptions many = one;
      many.threads = 3;  // more threads than cores: items still go out one at a time
      const CvReport a = cross_validate(Mlp{MlpConfig{.hidden = {6}, .epochs = 20}}, d.view(), one);
      const CvReport b =
          cross_validate(Mlp{MlpConfig{.hidden = {6}, .epochs = 20}}, d.view(), many);
      REQUIRE(a.ok());
      CHECK(a.predicted == b.predicted);
      CHECK(a.accuracy == b.accuracy);
      FiveByTwoOptions t1{.seed = 2, .snr_db = snr, .noise_target = target, .threads = 1};
      FiveByTwoOptions t3 = t1;
      t3.threads = 3;
      const FiveByTwoResult x = five_by_two_cv(LinearSvm{}, Knn{}, d.view(), t1);
      const FiveByTwoResult y = five_by_two_cv(LinearSvm{}, Knn{}, d.view(), t3);
      CHECK(x.differences == y.differences);
      CHECK(x.t == y.t);
      CHECK(x.mean_error_a == y.mean_error_a);
    }
  }
}

TEST_CASE("LinearSvm trains its one-vs-rest problems on several threads to the same model",
          "[learn][threads]") {
  const Dataset d = taxel_test::blobs(60, 5, 8, 1.5, 33);
  for (const SvmLoss loss : {SvmLoss::l2, SvmLoss::l1}) {
    // A max_iterations low enough that some problems stop there: the status names the first.
    for (const int iterations : {1000, 3}) {
      LinearSvmConfig one{.loss = loss, .max_iterations = iterations, .record_objective = true};
      one.threads = 1;
      LinearSvmConfig many = one;
      many.threads = 4;  // more threads than cores: problems still go out one at a time
      LinearSvm a(one), b(many);
      const Outcome oa = a.fit(d.view()), ob = b.fit(d.view());
      CHECK(oa.status == ob.status);
      CHECK(oa.message == ob.message);
      REQUIRE(a.weights().rows() == 5);
      CHECK(a.weights() == b.weights());
      CHECK(a.bias_weights() == b.bias_weights());
      CHECK(a.info().iterations == b.info().iterations);
      CHECK(a.info().objective == b.info().objective);
      CHECK(a.info().support_vectors == b.info().support_vectors);
      CHECK(a.info().trace == b.info().trace);
      CHECK(a.save() == b.save());
      if (iterations == 3) {
        CHECK(oa.status == Status::not_converged);
        CHECK_THAT(oa.message, Contains("max_iterations = 3"));
      }
    }
  }
  // Each problem has its own generator: the first is seeded by `seed` itself, so two classes
  // give the model a single generator seeded by `seed` would.
  const Dataset two = taxel_test::blobs(50, 2, 6, 1.0, 8);
  LinearSvm x(LinearSvmConfig{.seed = 7}), y(LinearSvmConfig{.seed = 8});
  REQUIRE(x.fit(two.view()).ok());
  REQUIRE(y.fit(two.view()).ok());
  CHECK(x.weights().rows() == 1);
  CHECK_FALSE(x.weights() == y.weights());  // the seed is used
}

namespace {
// A Knn that records the training threads each fit was given (ThreadedTraining).
struct ThreadProbe : Knn {
  unsigned own = 0;
  std::shared_ptr<std::vector<unsigned>> seen = std::make_shared<std::vector<unsigned>>();
  std::shared_ptr<std::mutex> mutex = std::make_shared<std::mutex>();
  [[nodiscard]] unsigned threads() const noexcept { return own; }
  void set_threads(unsigned n) noexcept { own = n; }
  Outcome fit(const DatasetView& d) {
    {
      const std::lock_guard<std::mutex> lock(*mutex);
      seen->push_back(own);
    }
    return Knn::fit(d);
  }
};
static_assert(ThreadedTraining<ThreadProbe>);
static_assert(ThreadedTraining<LinearSvm>);
static_assert(ThreadedTraining<Scaled<StandardScaler, LinearSvm>>);
static_assert(!ThreadedTraining<Scaled<StandardScaler, Knn>>);
}  // namespace

TEST_CASE("cross_validate and five_by_two_cv cap a classifier's own threads at theirs",
          "[learn][threads]") {
  const Dataset d = taxel_test::blobs(20, 3, 4, 1.0, 5);
  // (the classifier's own, the run's) -> what each fit gets: at most the run's, 0 meaning all.
  const std::vector<std::array<unsigned, 3>> cases = {{0, 1, 1}, {0, 0, 0}, {5, 3, 3},
                                                      {2, 3, 2}, {0, 2, 2}, {4, 0, 4}};
  for (const auto& [own, run, expected] : cases) {
    INFO("own " << own << ", run " << run);
    ThreadProbe probe;
    probe.own = own;
    REQUIRE(cross_validate(probe, d.view(), CvOptions{.folds = 4, .threads = run}).ok());
    CHECK(*probe.seen == std::vector<unsigned>(4, expected));
    probe.seen->clear();
    // (Knn against Knn: equal errors, so the t statistic is undefined; the fits all ran.)
    (void)five_by_two_cv(probe, Knn{}, d.view(), FiveByTwoOptions{.threads = run});
    CHECK(*probe.seen == std::vector<unsigned>(10, expected));
  }
  // Scaled passes them to the classifier it wraps.
  Scaled<StandardScaler, LinearSvm> scaled(LinearSvm(LinearSvmConfig{.threads = 6}));
  CHECK(scaled.threads() == 6);
  scaled.set_threads(2);
  CHECK(scaled.classifier().threads() == 2);
}

TEST_CASE("Student t CDF agrees with closed forms, quantiles give the 5x2cv thresholds",
          "[learn]") {
  for (const double t : {-3.0, -0.7, 0.0, 0.4, 1.3, 2.5, 8.0}) {
    INFO("t = " << t);
    CHECK(student_t_cdf(t, 1.0) == Approx(0.5 + std::atan(t) / std::numbers::pi).epsilon(1e-13));
    CHECK(student_t_cdf(t, 2.0) == Approx(0.5 + t / (2.0 * std::sqrt(2.0 + t * t))).epsilon(1e-13));
    const double th3 = std::atan(t / std::sqrt(3.0));
    CHECK(student_t_cdf(t, 3.0) ==
          Approx(0.5 + (th3 + std::sin(th3) * std::cos(th3)) / std::numbers::pi).epsilon(1e-13));
    const double th = std::atan(t / std::sqrt(5.0));
    const double c = std::cos(th);
    CHECK(student_t_cdf(t, 5.0) ==
          Approx(0.5 + (th + std::sin(th) * c * (1.0 + 2.0 / 3.0 * c * c)) / std::numbers::pi)
              .epsilon(1e-13));
  }
  CHECK(student_t_quantile(0.95, 5.0) == Approx(2.015048373).epsilon(1e-9));
  CHECK(student_t_quantile(0.975, 5.0) == Approx(2.570581836).epsilon(1e-9));
  CHECK(student_t_quantile(0.975, 1e6) == Approx(1.959966).epsilon(1e-5));
  CHECK_THROWS_AS(student_t_cdf(1.0, 0.0), std::invalid_argument);
}

TEST_CASE("5x2cv t test reproduces the hand-computed vector", "[learn]") {
  const FiveByTwoDifferences diff{
      {{0.02, 0.04}, {0.01, -0.01}, {0.03, 0.05}, {0.00, 0.02}, {0.04, 0.02}}};
  const FiveByTwoResult r = five_by_two_t_test(diff, 0.10);
  REQUIRE(r.ok());
  CHECK(r.t == Approx(1.4142135624).epsilon(1e-10));
  CHECK(r.p_value == Approx(0.2164372293).epsilon(1e-9));
  CHECK(r.critical == Approx(2.01505).epsilon(1e-5));
  CHECK_FALSE(r.reject);
  const FiveByTwoResult z = five_by_two_t_test(FiveByTwoDifferences{}, 0.05);
  CHECK(z.status == Status::degenerate);
  CHECK(z.p_value == 1.0);
  CHECK_THROWS_AS(five_by_two_t_test(diff, 1.5), std::invalid_argument);

  // On XOR, the RBF SVM is much better than the linear SVM: the test rejects.
  const Dataset d = taxel_test::xor_set(300, 0, 3);
  const FiveByTwoResult cmp =
      five_by_two_cv(LinearSvm{}, RbfSvm{RbfSvmConfig{.C = 10.0, .gamma = 2.0}}, d.view());
  REQUIRE(cmp.ok());
  CHECK(cmp.mean_error_a > cmp.mean_error_b + 0.2);
  CHECK(cmp.reject);
  CHECK(cmp.p_value < 0.05);
  // A classifier against itself: every difference is zero.
  CHECK(five_by_two_cv(LinearSvm{}, LinearSvm{}, d.view()).status == Status::degenerate);
}

TEST_CASE("White noise has the requested measured SNR", "[learn]") {
  FeatureMatrix x = FeatureMatrix::Constant(2000, 50, 3.0);
  x.row(7).setZero();
  const FeatureMatrix clean = x;
  std::mt19937_64 rng(5);
  add_white_noise(x, 10.0, rng);
  CHECK(x.row(7).isZero());
  const double signal = clean.squaredNorm();
  const double noise = (x - clean).squaredNorm();
  CHECK(10.0 * std::log10(signal / noise) == Approx(10.0).margin(0.05));
  CHECK_THROWS_AS(add_white_noise(x, NAN, rng), std::invalid_argument);
}

TEST_CASE("libsvm reader: features, groups, comments and round trip", "[io][learn]") {
  const std::string text =
      "# a comment line\n"
      "+1 qid:3 1:0.5 3:-2 # trailing comment\n"
      "\n"
      "-1 qid:4 2:1e-3\n"
      "2.0 qid:3 4:7\n";
  const Dataset d = taxel::io::parse_libsvm(text, "t.svm");
  REQUIRE(d.rows() == 3);
  CHECK(d.dims() == 4);
  CHECK(d.y == std::vector<int>{1, -1, 2});
  CHECK(d.groups == std::vector<int>{3, 4, 3});
  CHECK(d.x(0, 0) == 0.5);
  CHECK(d.x(0, 2) == -2.0);
  CHECK(d.x(1, 1) == 1e-3);
  CHECK(d.x(2, 3) == 7.0);
  CHECK(d.x(2, 0) == 0.0);
  const Dataset back = taxel::io::parse_libsvm(taxel::io::encode_libsvm(d.view()));
  CHECK(back.x == d.x);
  CHECK(back.y == d.y);
  CHECK(back.groups == d.groups);
  CHECK(taxel::io::parse_libsvm("1 2:1\n", "s", {.dims = 9}).dims() == 9);
}

TEST_CASE("libsvm reader errors name the line and column", "[io][learn]") {
  const auto bad = [](const std::string& text, const std::string& what,
                      taxel::io::LibsvmReadOptions opt = {}) {
    INFO(text);
    try {
      (void)taxel::io::parse_libsvm(text, "f.svm", opt);
      FAIL("no error");
    } catch (const taxel::IoError& e) {
      CHECK_THAT(e.what(), Contains(what));
    }
  };
  bad("1 1:2\n1.5 1:2\n", "f.svm:2: column 1: label `1.5` is not an integer");
  bad("abc 1:2\n", "f.svm:1: column 1: expected a numeric label");
  bad("1 2:1 1:1\n", "f.svm:1: column 7: feature index 1 does not follow 2");
  bad("1 0:1\n", "expected a feature index >= 1");
  bad("1 1:1 2\n", "column 7: expected <index>:<value>");
  bad("1 1:nan\n", "column 5: feature 1 is not finite");
  bad("1 1:\n", "expected a number after `1:`");
  bad("1 1:1x\n", "expected a number");
  bad("1 qid:1 1:1\n2 1:1\n", "f.svm:2: column 1: qid on some lines only");
  bad("1 1:1\n2 qid:1 1:1\n", "qid on some lines only");
  bad("1 1:1 qid:2\n", "qid must come right after the label");
  bad("", "no samples");
  bad("1\n2\n", "no features");
  bad("1 5:1\n", "feature index 5 exceeds the 3 features expected", {.dims = 3});
  bad("1 100000:1\n", "exceed the dense limit", {.max_values = 1000});
}

TEST_CASE("LinearSvm refuses features whose squared norm overflows instead of a zero model",
          "[learn][reliability]") {
  Dataset d = taxel_test::blobs(20, 2, 3, 4.0, 7);
  LinearSvm svm;
  REQUIRE(svm.fit(d.view()).ok());
  const Eigen::MatrixXd before = svm.weights();
  Dataset huge = d;
  huge.x *= 1e200;  // finite features, infinite ||x||^2
  const Outcome o = svm.fit(huge.view());
  CHECK(o.status == Status::invalid_input);
  CHECK_THAT(o.message, Contains("squared norm of sample 0") && Contains("overflows"));
  CHECK(svm.weights() == before);  // the previous model is kept
  // The same through the bias feature alone (-B 1e200).
  LinearSvm biased(LinearSvmConfig{.bias = 1e200});
  CHECK(biased.fit(d.view()).status == Status::invalid_input);
}
