// SPDX-License-Identifier: MIT
// taxel.learn: LinearSvm and its competitors (Knn, Lda, RbfSvm, Mlp) with fit / predict /
// decision_function on arrays, cross-validation, the 5x2cv test and LIBLINEAR model files.
#include "taxel/learn.hpp"
#include "common.hpp"
#include "taxel/io/file.hpp"
#include "taxel/io/libsvm_format.hpp"
#include "taxel/learn/model_file.hpp"

namespace taxel::python {
namespace {

namespace ln = taxel::learn;

using FeatureMap = Eigen::Map<const ln::FeatureMatrix>;

/// A data set viewing the arrays (no copy for C-contiguous float64 X and int32 y).
struct DataArrays {
  ArrayD x;
  ArrayI y;
  std::optional<ArrayI> groups;
  ln::DatasetView view() const {
    return {FeatureMap(x.data(), x.shape(0), x.shape(1)),
            {y.data(), static_cast<std::size_t>(y.size())},
            groups ? std::span<const int>(groups->data(), static_cast<std::size_t>(groups->size()))
                   : std::span<const int>{}};
  }
};

DataArrays data_arrays(ArrayD x, ArrayI y, std::optional<ArrayI> groups) {
  require_shape(x, {-1, -1}, "X", "(n_samples, n_features)");
  require_shape(y, {x.shape(0)}, "y", "(n_samples,) like X");
  if (groups) require_shape(*groups, {x.shape(0)}, "groups", "(n_samples,) like X");
  return {std::move(x), std::move(y), std::move(groups)};
}

void warn_not_converged(const Outcome& o) {
  if (o.status == Status::not_converged) {
    PyErr_WarnEx(PyExc_RuntimeWarning, o.message.c_str(), 1);
  }
}

constexpr std::pair<std::string_view, ln::SvmLoss> kLosses[] = {{"l2", ln::SvmLoss::l2},
                                                                {"l1", ln::SvmLoss::l1}};

constexpr std::pair<std::string_view, ln::KnnMetric> kMetrics[] = {
    {"euclidean", ln::KnnMetric::euclidean}, {"manhattan", ln::KnnMetric::manhattan}};

constexpr std::pair<std::string_view, ln::KnnWeighting> kWeighting[] = {
    {"uniform", ln::KnnWeighting::uniform}, {"distance", ln::KnnWeighting::distance}};

constexpr std::pair<std::string_view, ln::MlpActivation> kActivations[] = {
    {"tanh", ln::MlpActivation::tanh}, {"relu", ln::MlpActivation::relu}};

constexpr std::pair<std::string_view, ln::MlpOptimizer> kOptimizers[] = {
    {"adam", ln::MlpOptimizer::adam}, {"sgd", ln::MlpOptimizer::sgd}};
constexpr std::pair<std::string_view, ln::NoiseTarget> kNoiseTargets[] = {
    {"test_only", ln::NoiseTarget::test_only}, {"both", ln::NoiseTarget::both}};

template <class C>
constexpr const char* name_of() {
  if constexpr (std::is_same_v<C, ln::LinearSvm>) return "LinearSvm";
  if constexpr (std::is_same_v<C, ln::Knn>) return "Knn";
  if constexpr (std::is_same_v<C, ln::Lda>) return "Lda";
  if constexpr (std::is_same_v<C, ln::RbfSvm>) return "RbfSvm";
  return "Mlp";
}

/// The options cross_validate and five_by_two_cv share.
template <class Options>
void evaluation_options(Options& opt, std::uint64_t seed, bool grouped, double snr_db,
                        const std::string& noise_target, unsigned threads) {
  opt.seed = seed;
  opt.grouped = grouped;
  opt.snr_db = snr_db;
  opt.noise_target = enum_from(noise_target, kNoiseTargets, "noise_target");
  opt.threads = threads;
}

/// fit / predict / decision_function / classes_ for a Classifier.
template <class C>
py::class_<C> bind_classifier(py::module_& m, const char* name, const char* doc) {
  py::class_<C> cls(m, name, doc);
  // Every method takes the model's lock (common.hpp, object_mutex): fit exclusively, the rest
  // shared; the GIL is released before the lock is taken and taken back after it is released.
  cls.def(
         "fit",
         [](C& c, ArrayD x, ArrayI y, std::optional<ArrayI> groups) -> C& {
           const DataArrays d = data_arrays(std::move(x), std::move(y), std::move(groups));
           Outcome o;
           {
             py::gil_scoped_release release;
             const auto lock = write_lock(&c);
             o = c.fit(d.view());
           }
           raise_unless_ok(o, true);
           warn_not_converged(o);
           return c;
         },
         py::arg("X"), py::arg("y"), py::arg("groups") = py::none(),
         "Trains on X (n_samples, n_features) and integer labels y; returns self. ValueError "
         "for an empty set, non-finite features or one class; RuntimeWarning when an iteration "
         "cap stopped training (the model is still usable). Thread-safe: a model being fitted "
         "is not read meanwhile.")
      .def(
          "predict",
          [](const C& c, const ArrayD& x) {
            const auto fitted = [&] {
              if (c.dims() == 0) throw py::value_error(std::string(name_of<C>()) + ": not fitted");
            };
            if (x.ndim() == 1) {
              const auto lock = read_lock(&c);
              fitted();
              require_shape(x, {c.dims()}, "X", "(n_features,) or (n_samples, n_features)");
              return py::cast(c.predict(Eigen::Map<const Eigen::VectorXd>(x.data(), x.size())));
            }
            py::array_t<int> out(x.ndim() == 2 ? x.shape(0) : 0);
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&c);
              fitted();
              require_shape(x, {-1, c.dims()}, "X", "(n_samples, n_features)");
              for (py::ssize_t i = 0; i < x.shape(0); ++i) {
                out.mutable_data()[i] =
                    c.predict(Eigen::Map<const Eigen::VectorXd>(x.data() + i * c.dims(), c.dims()));
              }
            }
            return py::object(out);
          },
          py::arg("X"), "Labels of the rows of X (an int for a single 1-D sample).")
      .def(
          "decision_function",
          [](const C& c, const ArrayD& x) {
            py::ssize_t k = 0;
            {
              const auto lock = read_lock(&c);
              if (c.dims() == 0) throw py::value_error(std::string(name_of<C>()) + ": not fitted");
              k = static_cast<py::ssize_t>(c.classes().size());
            }
            ArrayD out({x.ndim() == 2 ? x.shape(0) : 0, k});
            py::gil_scoped_release release;
            const auto lock = read_lock(&c);
            require_shape(x, {-1, c.dims()}, "X", "(n_samples, n_features)");
            if (static_cast<py::ssize_t>(c.classes().size()) != k) {
              throw py::value_error(std::string(name_of<C>()) +
                                    ": the model was fitted again during the call");
            }
            for (py::ssize_t i = 0; i < x.shape(0); ++i) {
              Eigen::Map<Eigen::VectorXd> row(out.mutable_data() + i * k, k);
              c.decision(Eigen::Map<const Eigen::VectorXd>(x.data() + i * c.dims(), c.dims()), row);
            }
            return out;
          },
          py::arg("X"), "(n_samples, n_classes) decision values, columns in classes_ order.")
      .def_property_readonly(
          "classes_",
          [](const C& c) {
            const auto lock = read_lock(&c);
            const auto cl = c.classes();
            return vector_array(std::vector<int>(cl.begin(), cl.end()));
          },
          "labels in the model's order")
      .def_property_readonly("n_features_in_",
                             [](const C& c) {
                               const auto lock = read_lock(&c);
                               return c.dims();
                             })
      .def(
          "to_bytes",
          [](const C& c) {
            std::string bytes;
            {
              const auto lock = read_lock(&c);
              bytes = ln::encode_model(c);
            }
            return py::bytes(bytes);
          },
          "The model (options, classes, what it learned) as taxel's versioned model bytes.")
      .def_static(
          "from_bytes",
          [](const py::bytes& b, const std::string& source) {
            return ln::decode_model<C>(
                std::string_view(b),
                source.empty() ? std::string(name_of<C>()) + " bytes" : source);
          },
          py::arg("data"), py::arg("source") = "",
          "A model from to_bytes(); taxel.IoError naming `source` for damaged bytes.")
      .def(py::pickle(
          [](const C& c) {
            const auto lock = read_lock(&c);
            return py::make_tuple(py::bytes(ln::encode_model(c)));
          },
          [](const py::tuple& t) {
            if (t.size() != 1 || !py::isinstance<py::bytes>(t[0])) {
              throw py::value_error(std::string(name_of<C>()) + ": not a pickled model state");
            }
            return ln::decode_model<C>(std::string_view(t[0].cast<py::bytes>()),
                                       std::string("pickled ") + name_of<C>());
          }))
      .def(
          "__deepcopy__",
          [](const C& c, const py::dict&) {
            const auto lock = read_lock(&c);
            return C(c);
          },
          py::arg("memo"));
  return cls;
}

/// Calls fn(classifier) with the C++ classifier held by `obj`.
template <class Fn>
auto with_classifier(const py::object& obj, Fn&& fn) {
  if (py::isinstance<ln::LinearSvm>(obj)) return fn(obj.cast<const ln::LinearSvm&>());
  if (py::isinstance<ln::Knn>(obj)) return fn(obj.cast<const ln::Knn&>());
  if (py::isinstance<ln::Lda>(obj)) return fn(obj.cast<const ln::Lda&>());
  if (py::isinstance<ln::RbfSvm>(obj)) return fn(obj.cast<const ln::RbfSvm&>());
  if (py::isinstance<ln::Mlp>(obj)) return fn(obj.cast<const ln::Mlp&>());
  throw py::type_error(
      "expected a taxel.learn classifier (LinearSvm, Knn, Lda, RbfSvm, Mlp), got " +
      std::string(py::str(py::type::of(obj))));
}

}  // namespace

void bind_learn(py::module_& root) {
  py::module_ m = root.def_submodule("learn", R"doc(
Classifiers on feature arrays, with scikit-learn-like fit / predict / decision_function.
LinearSvm reproduces LIBLINEAR 2.3 (-s 1 / -s 3, one-vs-rest) and reads and writes its model
files.)doc");

  bind_classifier<ln::LinearSvm>(
      m, "LinearSvm",
      "Linear SVM, LIBLINEAR's dual coordinate descent: loss 'l2' "
      "(-s 1, default) or 'l1' (-s 3); C (-c), eps (-e), bias (-B), "
      "class_weights {label: w} (-wi); threads trains the one-vs-rest problems at once (0: "
      "every core; the model does not depend on it).")
      .def(py::init([](double C, const std::string& loss, double eps, double bias,
                       int max_iterations, bool shrinking, std::uint64_t seed,
                       const std::map<int, double>& class_weights, unsigned threads) {
             ln::LinearSvmConfig c;
             c.C = C;
             c.loss = enum_from(loss, kLosses, "loss");
             c.eps = eps;
             c.bias = bias;
             c.max_iterations = max_iterations;
             c.shrinking = shrinking;
             c.seed = seed;
             c.class_weights.assign(class_weights.begin(), class_weights.end());
             c.threads = threads;
             return ln::LinearSvm(c);
           }),
           py::kw_only(), py::arg("C") = 1.0, py::arg("loss") = "l2", py::arg("eps") = 0.1,
           py::arg("bias") = -1.0, py::arg("max_iterations") = 1000, py::arg("shrinking") = true,
           py::arg("seed") = 1, py::arg("class_weights") = std::map<int, double>{},
           py::arg("threads") = 0u)
      .def_property_readonly(
          "coef_",
          [](const ln::LinearSvm& s) {
            const auto lock = read_lock(&s);
            return std::decay_t<decltype(s.weights())>(s.weights());
          },
          "(n_problems, n_features) weights; one row for two classes")
      .def_property_readonly(
          "intercept_",
          [](const ln::LinearSvm& s) {
            const auto lock = read_lock(&s);
            return Eigen::VectorXd(s.bias() >= 0 ? Eigen::VectorXd(s.bias() * s.bias_weights())
                                                 : Eigen::VectorXd::Zero(s.bias_weights().size()));
          },
          "(n_problems,) intercepts: bias * bias weight")
      .def_property_readonly("solver_type", &ln::LinearSvm::solver_type)
      .def_property_readonly(
          "bias",
          [](const ln::LinearSvm& s) {
            const auto lock = read_lock(&s);
            return s.bias();
          },
          "the bias feature's value the model was trained with (< 0: none)")
      .def_property_readonly("iterations",
                             [](const ln::LinearSvm& s) {
                               const auto lock = read_lock(&s);
                               return s.info().iterations;
                             })
      .def_property_readonly(
          "objective",
          [](const ln::LinearSvm& s) {
            const auto lock = read_lock(&s);
            return s.info().objective;
          },
          "final dual objective per binary problem")
      .def(
          "to_liblinear",
          [](const ln::LinearSvm& s) {
            const auto lock = read_lock(&s);
            return s.save();
          },
          "the model as LIBLINEAR model-file text")
      .def_static(
          "from_liblinear", [](const std::string& text) { return ln::LinearSvm::load(text); },
          py::arg("text"), "a model from LIBLINEAR model-file text")
      .def(
          "save",
          [](const ln::LinearSvm& s, const std::string& path) { io::write_file(path, s.save()); },
          py::arg("path"), "Writes a LIBLINEAR model file (atomically; OSError on failure).")
      .def_static(
          "load",
          [](const std::string& path) { return ln::LinearSvm::load(io::read_file(path), path); },
          py::arg("path"), "Reads a LIBLINEAR model file (any classification solver).");

  bind_classifier<ln::Knn>(m, "Knn", "k nearest neighbours; decision values are vote shares.")
      .def(py::init([](int k, const std::string& metric, const std::string& weighting) {
             return ln::Knn(ln::KnnConfig{k, enum_from(metric, kMetrics, "metric"),
                                          enum_from(weighting, kWeighting, "weighting")});
           }),
           py::kw_only(), py::arg("k") = 5, py::arg("metric") = "euclidean",
           py::arg("weighting") = "uniform");

  bind_classifier<ln::Lda>(m, "Lda",
                           "Linear discriminant analysis with optional shrinkage (negative: "
                           "Ledoit-Wolf).")
      .def(py::init([](double shrinkage, bool empirical_priors) {
             return ln::Lda(ln::LdaConfig{shrinkage, empirical_priors});
           }),
           py::kw_only(), py::arg("shrinkage") = 0.0, py::arg("empirical_priors") = true);

  bind_classifier<ln::RbfSvm>(m, "RbfSvm",
                              "Kernel SVM with K = exp(-gamma |x - z|^2) (LIBSVM's C-SVC, "
                              "one-vs-one); gamma 0 means 1 / n_features.")
      .def(py::init(
               [](double C, double gamma, double eps, double cache_mb, long long max_iterations) {
                 return ln::RbfSvm(ln::RbfSvmConfig{C, gamma, eps, cache_mb, max_iterations});
               }),
           py::kw_only(), py::arg("C") = 1.0, py::arg("gamma") = 0.0, py::arg("eps") = 1e-3,
           py::arg("cache_mb") = 100.0, py::arg("max_iterations") = 0)
      .def(
          "pair_decision_function",
          [](const ln::RbfSvm& c, const ArrayD& x) {
            const auto lock = read_lock(&c);
            if (c.dims() == 0) throw py::value_error("RbfSvm: not fitted");
            require_shape(x, {-1, c.dims()}, "X", "(n_samples, n_features)");
            const auto k = static_cast<py::ssize_t>(c.classes().size());
            ArrayD out({x.shape(0), k * (k - 1) / 2});
            py::gil_scoped_release release;
            for (py::ssize_t i = 0; i < x.shape(0); ++i) {
              Eigen::Map<Eigen::VectorXd> row(out.mutable_data() + i * out.shape(1), out.shape(1));
              c.pair_decision(Eigen::Map<const Eigen::VectorXd>(x.data() + i * c.dims(), c.dims()),
                              row);
            }
            return out;
          },
          py::arg("X"),
          "(n_samples, k (k - 1) / 2) raw one-vs-one values, LIBSVM's pair order (0, 1), "
          "(0, 2), ..., (1, 2), ...; positive favours the pair's first class in classes_.")
      .def_property_readonly(
          "support_vectors_",
          [](const ln::RbfSvm& c) {
            const auto lock = read_lock(&c);
            return ln::FeatureMatrix(c.support_vectors());
          },
          "(n_support, n_features) support vectors, in training order");

  bind_classifier<ln::Mlp>(m, "Mlp",
                           "Multi-layer perceptron (one or two hidden layers, softmax output); "
                           "decision values are class probabilities.")
      .def(py::init([](std::vector<int> hidden, const std::string& activation,
                       const std::string& optimizer, double learning_rate, double momentum,
                       double l2, int epochs, int batch_size, double tolerance, int patience,
                       std::uint64_t seed) {
             return ln::Mlp(
                 ln::MlpConfig{std::move(hidden), enum_from(activation, kActivations, "activation"),
                               enum_from(optimizer, kOptimizers, "optimizer"), learning_rate,
                               momentum, l2, epochs, batch_size, tolerance, patience, seed});
           }),
           py::kw_only(), py::arg("hidden") = std::vector<int>{32}, py::arg("activation") = "tanh",
           py::arg("optimizer") = "adam", py::arg("learning_rate") = 1e-2,
           py::arg("momentum") = 0.9, py::arg("l2") = 1e-4, py::arg("epochs") = 200,
           py::arg("batch_size") = 32, py::arg("tolerance") = 1e-5, py::arg("patience") = 10,
           py::arg("seed") = 1);

  py::class_<ln::CvReport> cls_cvreport(m, "CvReport", "Out-of-fold results of cross_validate.");
  pickle_members(cls_cvreport, "CvReport", &ln::CvReport::status, &ln::CvReport::message,
                 &ln::CvReport::classes, &ln::CvReport::confusion,
                 &ln::CvReport::per_class_accuracy, &ln::CvReport::accuracy,
                 &ln::CvReport::predicted, &ln::CvReport::fold);
  cls_cvreport
      .def_property_readonly("status",
                             [](const ln::CvReport& r) { return std::string(to_string(r.status)); })
      .def_readonly("message", &ln::CvReport::message, "why, when status is not 'ok'")
      .def_readonly("accuracy", &ln::CvReport::accuracy, "fraction of samples predicted right")
      .def_property_readonly("classes",
                             [](const ln::CvReport& r) { return vector_array(r.classes); })
      .def_readonly("confusion", &ln::CvReport::confusion,
                    "[true class][predicted class], in `classes` order")
      .def_readonly("per_class_accuracy", &ln::CvReport::per_class_accuracy,
                    "recall of each class, in `classes` order")
      .def_property_readonly("predicted",
                             [](const ln::CvReport& r) { return vector_array(r.predicted); })
      .def_property_readonly("fold", [](const ln::CvReport& r) { return vector_array(r.fold); });

  m.def(
      "cross_validate",
      [](const py::object& model, ArrayD x, ArrayI y, std::optional<ArrayI> groups, int folds,
         std::uint64_t seed, bool grouped, double snr_db, const std::string& noise_target,
         unsigned threads) {
        const DataArrays d = data_arrays(std::move(x), std::move(y), std::move(groups));
        ln::CvOptions opt;
        opt.folds = folds;
        evaluation_options(opt, seed, grouped, snr_db, noise_target, threads);
        ln::CvReport r = with_classifier(model, [&](const auto& c) {
          py::gil_scoped_release release;
          return ln::cross_validate(c, d.view(), opt);
        });
        raise_unless_ok(r, true);
        warn_not_converged(r);
        return r;
      },
      py::arg("model"), py::arg("X"), py::arg("y"), py::arg("groups") = py::none(), py::kw_only(),
      py::arg("folds") = 5, py::arg("seed") = 1, py::arg("grouped") = false,
      py::arg("snr_db") = std::numeric_limits<double>::infinity(),
      py::arg("noise_target") = "test_only", py::arg("threads") = 0,
      "Stratified k-fold cross-validation of an (unfitted) classifier; grouped keeps each "
      "group in one fold; snr_db adds white noise to the test (or both) features. The folds "
      "train on `threads` threads (0: every core); the report does not depend on it.");

  py::class_<ln::FiveByTwoResult> cls_fivebytworesult(m, "FiveByTwoResult",
                                                      "Dietterich's 5x2cv paired t test.");
  pickle_members(cls_fivebytworesult, "FiveByTwoResult", &ln::FiveByTwoResult::status,
                 &ln::FiveByTwoResult::message, &ln::FiveByTwoResult::differences,
                 &ln::FiveByTwoResult::t, &ln::FiveByTwoResult::p_value,
                 &ln::FiveByTwoResult::alpha, &ln::FiveByTwoResult::critical,
                 &ln::FiveByTwoResult::reject, &ln::FiveByTwoResult::mean_error_a,
                 &ln::FiveByTwoResult::mean_error_b);
  cls_fivebytworesult
      .def_property_readonly(
          "status", [](const ln::FiveByTwoResult& r) { return std::string(to_string(r.status)); })
      .def_readonly("message", &ln::FiveByTwoResult::message, "why, when status is not 'ok'")
      .def_property_readonly(
          "differences",
          [](const ln::FiveByTwoResult& r) {
            ArrayD out({5, 2});
            for (int i = 0; i < 5; ++i) {
              for (int j = 0; j < 2; ++j) out.mutable_data()[2 * i + j] = r.differences[i][j];
            }
            return out;
          },
          "(5, 2) error of A minus error of B per replication and fold")
      .def_readonly("t", &ln::FiveByTwoResult::t, "the 5x2cv t statistic")
      .def_readonly("p_value", &ln::FiveByTwoResult::p_value,
                    "two-sided p-value, Student t with 5 degrees of freedom")
      .def_readonly("alpha", &ln::FiveByTwoResult::alpha, "significance level")
      .def_readonly("critical", &ln::FiveByTwoResult::critical, "|t| above this rejects")
      .def_readonly("reject", &ln::FiveByTwoResult::reject,
                    "whether equal error rates are rejected")
      .def_readonly("mean_error_a", &ln::FiveByTwoResult::mean_error_a,
                    "mean error rate of A over the ten folds")
      .def_readonly("mean_error_b", &ln::FiveByTwoResult::mean_error_b,
                    "mean error rate of B over the ten folds");

  m.def(
      "five_by_two_t_test",
      [](const ArrayD& differences, double alpha) {
        require_shape(differences, {5, 2}, "differences", "(5, 2)");
        ln::FiveByTwoDifferences d{};
        for (int i = 0; i < 5; ++i) {
          for (int j = 0; j < 2; ++j) d[i][j] = differences.data()[2 * i + j];
        }
        return ln::five_by_two_t_test(d, alpha);
      },
      py::arg("differences"), py::arg("alpha") = 0.05,
      "The 5x2cv t statistic, p-value and decision from the (5, 2) error differences.");

  m.def(
      "five_by_two_cv",
      [](const py::object& a, const py::object& b, ArrayD x, ArrayI y, std::optional<ArrayI> groups,
         double alpha, std::uint64_t seed, bool grouped, double snr_db,
         const std::string& noise_target, unsigned threads) {
        const DataArrays d = data_arrays(std::move(x), std::move(y), std::move(groups));
        ln::FiveByTwoOptions opt;
        opt.alpha = alpha;
        evaluation_options(opt, seed, grouped, snr_db, noise_target, threads);
        ln::FiveByTwoResult r = with_classifier(a, [&](const auto& ca) {
          return with_classifier(b, [&](const auto& cb) {
            py::gil_scoped_release release;
            return ln::five_by_two_cv(ca, cb, d.view(), opt);
          });
        });
        if (r.status == Status::invalid_input) raise_unless_ok(r);
        return r;
      },
      py::arg("a"), py::arg("b"), py::arg("X"), py::arg("y"), py::arg("groups") = py::none(),
      py::kw_only(), py::arg("alpha") = 0.05, py::arg("seed") = 1, py::arg("grouped") = false,
      py::arg("snr_db") = std::numeric_limits<double>::infinity(),
      py::arg("noise_target") = "test_only", py::arg("threads") = 0,
      "Dietterich's 5x2cv paired t test of two (unfitted) classifiers on the same splits; the "
      "ten rounds run on `threads` threads (0: every core).");

  m.def(
      "read_libsvm",
      [](const std::string& path) {
        ln::Dataset d = io::read_libsvm(path);
        return py::make_tuple(ln::FeatureMatrix(std::move(d.x)), vector_array(d.y));
      },
      py::arg("path"), "(X, y) from a LIBSVM/LIBLINEAR data file (OSError naming the line).");
  m.def(
      "write_libsvm",
      [](const std::string& path, ArrayD x, ArrayI y) {
        const DataArrays d = data_arrays(std::move(x), std::move(y), std::nullopt);
        io::write_file(path, io::encode_libsvm(d.view()));
      },
      py::arg("path"), py::arg("X"), py::arg("y"), "Writes X and y as a LIBSVM data file.");
}

}  // namespace taxel::python
