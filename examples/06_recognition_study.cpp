// SPDX-License-Identifier: MIT
// 06_recognition_study: reruns the second paper's recognition study on
// SYNTHETIC palm-grasp pressure images from taxel::sim::PalmGraspSynth:
//  - Table 2: conventional (11 regional descriptors) vs hybrid (1024 gradient magnitudes of the
//    reconstruction + 11) recognition with a linear SVM and 5-fold cross-validation;
//  - the same with subject-grouped folds (no subject in both training and test);
//  - Table 3: Dietterich's 5x2cv paired t test of the LSVM against LDA, RBF-SVM, kNN and MLP;
//  - Fig. 5: accuracy against the SNR of white noise added to the test features;
//  - time per image of each scheme.
// Writes the data set (NPY stack, labels, libsvm feature files), sample pictures, an SVG plot
// and the printed report into the output folder.
#include <algorithm>
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <taxel/image.hpp>
#include <taxel/io.hpp>
#include <taxel/learn.hpp>
#include <taxel/sim/palm_grasp.hpp>
#include <vector>

#include "cli.hpp"

#if defined(TAXEL_EXAMPLES_HAVE_PNG)
#include <taxel/io/png.hpp>
#endif

namespace {

namespace ti = taxel::image;
namespace tl = taxel::learn;
namespace ts = taxel::sim;
using Clock = std::chrono::steady_clock;

constexpr const char* kUsage = R"usage(usage: 06_recognition_study [options]

Reruns the second paper's study (conventional vs hybrid recognition, 5x2cv t tests against
LDA, RBF-SVM, kNN and MLP, accuracy against feature noise) on synthetic palm-grasp images.

options:
  --subjects N   subjects (default 50: 50 x 4 classes x 10 grasps x 2 hands = 4000 images)
  --grasps N     grasps per subject, class and hand (default 10)
  --seed S       synthesiser and evaluation seed (default 1)
  --out DIR      output folder (default recognition-study)
  --quick        5 subjects: a smoke run of every step
  --threads N    folds, replications, noise levels and each SVM's one-vs-rest problems on N
                 threads (default 0: every core); the tables are the same for any N
  -h, --help     show this help
)usage";

struct Options {
  int subjects = 50;
  int grasps = 10;
  std::uint64_t seed = 1;
  std::string out = "recognition-study";
  unsigned threads = 0;
};

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "06_recognition_study: %s\n", why.c_str());
  std::exit(1);
}

Options parse(int argc, char** argv) {
  taxel_cli::Args args("06_recognition_study", argc, argv);
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--subjects") {
      o.subjects = args.number<int>(2, 1000);
    } else if (a == "--grasps") {
      o.grasps = args.number<int>(1, 1000);
    } else if (a == "--seed") {
      o.seed = args.number<std::uint64_t>(0, std::numeric_limits<std::uint64_t>::max());
    } else if (a == "--out") {
      o.out = std::string(args.value());
    } else if (a == "--quick") {
      o.subjects = 5;
    } else if (a == "--threads") {
      o.threads = args.number<unsigned>(0, 4096);
    } else {
      args.fail("unknown argument '" + std::string(a) + "' (see --help)");
    }
  }
  if (o.subjects * o.grasps * 8 < 40) args.fail("too few images for 5-fold cross-validation");
  return o;
}

// The report goes to standard output and to report.txt.
std::string g_report;
// Threads for the folds, replications and noise levels (--threads).
unsigned g_threads = 0;
[[gnu::format(printf, 1, 2)]] void say(const char* fmt, ...) {
  std::string line;
  va_list ap;
  va_start(ap, fmt);
  taxel_cli::vappendf(line, fmt, ap);
  va_end(ap);
  std::fputs(line.c_str(), stdout);
  std::fflush(stdout);
  g_report += line;
}

// Progress on standard error, overwritten in place (from any thread).
void progress(const char* stage, std::size_t done, std::size_t total) {
  static std::mutex mutex;
  const std::lock_guard<std::mutex> lock(mutex);
  std::fprintf(stderr, "\r  %s %zu/%zu ", stage, done, total);
  if (done == total) std::fputs("\r\033[K", stderr);
  std::fflush(stderr);
}
tl::ProgressFn progress_fn(const char* stage) {
  return [stage](std::size_t d, std::size_t t) { progress(stage, d, t); };
}

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The edged/edgeless decision of the ablations: none (RecEdgeless always), or the true class.
struct FixedDecision {
  const bool* truth = nullptr;  // null: always edgeless
  [[nodiscard]] bool edged(const Eigen::VectorXd& /*f*/) const { return truth && *truth; }
};

using Lsvm = tl::Scaled<tl::StandardScaler, tl::LinearSvm>;
Lsvm make_lsvm() {
  // z-scored features, L2-loss dual CD; C = 0.01 regularises the 1035-dimensional hybrid vector
  // (the same C for both schemes).
  tl::LinearSvmConfig c;
  c.C = 0.01;
  c.threads = g_threads;  // each fit's one-vs-rest problems too
  return Lsvm(tl::LinearSvm(c));
}

bool is_edged(ts::GraspClass c) {
  return c == ts::GraspClass::one_edged || c == ts::GraspClass::two_edged;
}

// Hybrid features of every image with the decider `D`.
template <class D>
tl::Dataset hybrid_features(const std::vector<ts::PalmGraspSample>& data, const D& decider,
                            const bool* truth_slot, bool* truth) {
  ti::Recognizer<D> rec(32, 32, {}, decider);
  tl::Dataset d;
  d.x.resize(static_cast<Eigen::Index>(data.size()), 32 * 32 + ti::kRegionalFeatures);
  for (std::size_t i = 0; i < data.size(); ++i) {
    if (truth_slot != nullptr) *truth = is_edged(data[i].label);
    d.x.row(static_cast<Eigen::Index>(i)) = rec.recognize(data[i].image).hybrid.transpose();
    d.y.push_back(static_cast<int>(data[i].label));
    d.groups.push_back(data[i].subject);
  }
  return d;
}

// Accuracy at each SNR of white noise on the test features; each fold's model is trained once
// on clean features and tested at every SNR (noise on test data only; the paper does not say which
// side gets it). The noise goes on the raw feature vector (`raw`) or on the vector after the
// training folds' z-scoring (`standardised`, every feature at unit scale).
struct SnrCurves {
  std::vector<double> raw;
  std::vector<double> standardised;
};
SnrCurves accuracy_vs_snr(const tl::Dataset& d, const std::vector<int>& fold,
                          const std::vector<double>& snr, std::uint64_t seed, const char* stage) {
  SnrCurves acc{std::vector<double>(snr.size(), 0.0), std::vector<double>(snr.size(), 0.0)};
  const int k = 1 + *std::max_element(fold.begin(), fold.end());
  // The folds in parallel, each counting its own hits; the counts are whole numbers, so their
  // sum does not depend on the order.
  std::vector<SnrCurves> hits(static_cast<std::size_t>(k), acc);
  std::atomic<std::size_t> done{0};
  taxel::parallel_for(static_cast<std::size_t>(k), g_threads, [&](std::size_t fi) {
    const int f = static_cast<int>(fi);
    std::vector<std::size_t> train, test;
    for (std::size_t i = 0; i < fold.size(); ++i) (fold[i] == f ? test : train).push_back(i);
    const tl::Dataset tr = tl::subset(d.view(), train);
    const tl::Dataset te = tl::subset(d.view(), test);
    Lsvm model = make_lsvm();
    const taxel::Outcome o = model.fit(tr.view());
    if (!o && o.status != taxel::Status::not_converged) {
      throw std::runtime_error(std::string(stage) + ": " + o.message);  // rethrown below
    }
    for (std::size_t s = 0; s < snr.size(); ++s) {
      for (const bool standardise : {false, true}) {
        tl::FeatureMatrix x = te.x;
        if (standardise) model.scaler().transform_in_place(x);
        std::mt19937_64 rng(seed * 1000003U + static_cast<std::uint64_t>(f) * 131U + s);
        if (std::isfinite(snr[s])) tl::add_white_noise(x, snr[s], rng);
        double& h = (standardise ? hits[fi].standardised : hits[fi].raw)[s];
        for (Eigen::Index i = 0; i < x.rows(); ++i) {
          const Eigen::VectorXd row = x.row(i).transpose();
          const int label = standardise ? model.classifier().predict(row) : model.predict(row);
          h += label == te.y[static_cast<std::size_t>(i)] ? 1.0 : 0.0;
        }
      }
    }
    progress(stage, done.fetch_add(1) + 1, static_cast<std::size_t>(k));
  });
  for (const SnrCurves& h : hits) {
    for (std::size_t s = 0; s < snr.size(); ++s) {
      acc.raw[s] += h.raw[s];
      acc.standardised[s] += h.standardised[s];
    }
  }
  for (auto* v : {&acc.raw, &acc.standardised}) {
    for (double& c : *v) c = 100.0 * c / static_cast<double>(fold.size());
  }
  return acc;
}

double percent_of_class(const tl::CvReport& r, int label) {
  const int i = tl::class_index(r.classes, label);
  return i < 0 ? std::nan("") : 100.0 * r.per_class_accuracy(i);
}

tl::CvReport cv_or_die(const tl::Dataset& d, bool grouped, std::uint64_t seed, const char* stage) {
  tl::CvOptions opt;
  opt.grouped = grouped;
  opt.seed = seed;
  opt.progress = progress_fn(stage);
  opt.threads = g_threads;
  tl::CvReport r = tl::cross_validate(make_lsvm(), d.view(), opt);
  if (!r && r.status != taxel::Status::not_converged) die(std::string(stage) + ": " + r.message);
  return r;
}

void write_picture(const std::filesystem::path& stem, const taxel::io::RgbImage& pic,
                   std::vector<std::string>& written) {
#if defined(TAXEL_EXAMPLES_HAVE_PNG)
  const auto file = stem.string() + ".png";
  taxel::io::write_png(file, pic);
#else
  const auto file = stem.string() + ".ppm";
  taxel::io::write_file(file, taxel::io::encode_ppm(pic));
#endif
  written.push_back(file);
}

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("06_recognition_study");
  const Options opt = parse(argc, argv);
  g_threads = opt.threads;
  const auto start = Clock::now();
  const std::filesystem::path out(opt.out);
  std::filesystem::create_directories(out);
  std::vector<std::string> written;

  say("taxel 06_recognition_study: the second paper's study on SYNTHETIC palm-grasp images\n");
  say("(model and assumptions: include/taxel/sim/palm_grasp.hpp; the paper's 4000 PPS images are "
      "not public)\n\n");

  // 1. Data. The libsvm files carry no qid (LIBLINEAR refuses it); subjects are in labels.txt.
  auto t0 = Clock::now();
  const ts::PalmGraspSynth synth({}, opt.seed);
  const std::vector<ts::PalmGraspSample> data = synth.dataset(opt.subjects, opt.grasps);
  const std::size_t n = data.size();
  say("data: %d subjects x 4 classes x %d grasps x 2 hands = %zu images of 32 x 32 (%.2f s)\n",
      opt.subjects, opt.grasps, n, seconds_since(t0));

  // 2. Features with the paper's chain and rule (Gm > Gth = 25).
  t0 = Clock::now();
  ti::Recognizer<> rec(32, 32);
  tl::Dataset conv;
  tl::Dataset hyb;
  conv.x.resize(static_cast<Eigen::Index>(n), ti::kRegionalFeatures);
  hyb.x.resize(static_cast<Eigen::Index>(n), 32 * 32 + ti::kRegionalFeatures);
  std::vector<std::vector<double>> gm(5);
  std::vector<int> called_edged(5, 0);
  std::vector<int> per_class(5, 0);
  taxel::io::ImageStack stack{static_cast<Eigen::Index>(n), 32, 32, {}};
  stack.values.reserve(n * 1024);
  std::string labels =
      "# label subject hand grasp (label: 1 planar, 2 one-edged, 3 two-edged, "
      "4 cylindrical; hand: R or L)\n";
  for (std::size_t i = 0; i < n; ++i) {
    const ts::PalmGraspSample& s = data[i];
    const ti::Recognition& r = rec.recognize(s.image);
    if (!r.ok()) die("image " + std::to_string(i) + ": " + r.message);
    const auto row = static_cast<Eigen::Index>(i);
    conv.x.row(row) = r.regional.transpose();
    hyb.x.row(row) = r.hybrid.transpose();
    const int label = static_cast<int>(s.label);
    for (auto* d : {&conv, &hyb}) {
      d->y.push_back(label);
      d->groups.push_back(s.subject);
    }
    gm[static_cast<std::size_t>(label)].push_back(r.contour_gradient);
    called_edged[static_cast<std::size_t>(label)] += r.edged ? 1 : 0;
    ++per_class[static_cast<std::size_t>(label)];
    // Row-major frame (ImageD is row-major).
    stack.values.insert(stack.values.end(), s.image.data(), s.image.data() + s.image.size());
    labels += std::to_string(label) + " " + std::to_string(s.subject) + " " +
              (s.right_hand ? "R " : "L ") + std::to_string(s.grasp) + "\n";
    if ((i + 1) % 100 == 0 || i + 1 == n) progress("features", i + 1, n);
  }
  say("features: 11 regional + 1035 hybrid per image (%.2f s)\n", seconds_since(t0));
  taxel::io::write_file((out / "images.npy").string(),
                        taxel::io::encode_npy(stack, taxel::io::NpyDtype::u1));
  taxel::io::write_file((out / "labels.txt").string(), labels);
  taxel::io::write_file((out / "conventional.libsvm").string(),
                        taxel::io::encode_libsvm(tl::DatasetView{conv.x, conv.y}));
  taxel::io::write_file((out / "hybrid.libsvm").string(),
                        taxel::io::encode_libsvm(tl::DatasetView{hyb.x, hyb.y}));
  for (const char* f : {"images.npy", "labels.txt", "conventional.libsvm", "hybrid.libsvm"}) {
    written.push_back((out / f).string());
  }

  say("\nEdged/edgeless decision, the paper's rule Gm > Gth = 25 (Gm: mean Sobel magnitude on the"
      "\ncontour of the largest HPR; 0 when no HPR of 50 px survives)\n");
  say("%-12s %8s %8s %8s %14s\n", "class", "Gm p5", "p50", "p95", "called edged");
  for (ts::GraspClass c : ts::kGraspClasses) {
    auto v = gm[static_cast<std::size_t>(c)];
    std::sort(v.begin(), v.end());
    const auto q = [&](double p) {
      return v[static_cast<std::size_t>(p * static_cast<double>(v.size() - 1))];
    };
    say("%-12s %8.0f %8.0f %8.0f %13.1f%%\n", std::string(ts::to_string(c)).c_str(), q(0.05),
        q(0.5), q(0.95),
        100.0 * called_edged[static_cast<std::size_t>(c)] / per_class[static_cast<std::size_t>(c)]);
  }

  // 3. Table 2.
  say("\nTable 2: linear SVM (z-scored, C = 0.01), stratified 5-fold CV, accuracy %% "
      "(paper's values in brackets)\n");
  const tl::CvReport conv_cv = cv_or_die(conv, false, opt.seed, "Table 2, conventional: fold");
  const tl::CvReport hyb_cv = cv_or_die(hyb, false, opt.seed, "Table 2, hybrid: fold");
  static constexpr double kPaperConv[] = {100.0, 93.46, 89.73, 87.21};
  static constexpr double kPaperHyb[] = {100.0, 98.09, 96.17, 96.24};
  say("%-12s %22s %22s\n", "class", "conventional (11)", "hybrid (1035)");
  for (std::size_t k = 0; k < 4; ++k) {
    const int label = static_cast<int>(ts::kGraspClasses[k]);
    say("%-12s %13.2f (%6.2f) %13.2f (%6.2f)\n",
        std::string(ts::to_string(ts::kGraspClasses[k])).c_str(), percent_of_class(conv_cv, label),
        kPaperConv[k], percent_of_class(hyb_cv, label), kPaperHyb[k]);
  }
  say("%-12s %13.2f (%6.2f) %13.2f (%6.2f)\n", "mean", 100.0 * conv_cv.accuracy, 92.60,
      100.0 * hyb_cv.accuracy, 97.62);

  // Time per image: features of one image plus the trained model's decision.
  Lsvm conv_model = make_lsvm();
  Lsvm hyb_model = make_lsvm();
  (void)conv_model.fit(conv.view());
  (void)hyb_model.fit(hyb.view());
  ti::Segmenter segmenter({}, 32, 32);
  ti::RegionAnalyzer analyzer(
      ti::RegionPropsOptions{.zero_based = false, .convex = true, .perimeter = false}, 32, 32);
  Eigen::VectorXd regional(ti::kRegionalFeatures);
  const std::size_t timed = std::min<std::size_t>(n, 2000);
  double conv_us = std::numeric_limits<double>::infinity();
  double hyb_us = conv_us;
  long long sink = 0;
  for (int rep = 0; rep < 3; ++rep) {
    t0 = Clock::now();
    for (std::size_t i = 0; i < timed; ++i) {
      ti::regional_features(analyzer.compute(segmenter.run(data[i].image).high), regional);
      sink += conv_model.predict(regional);
    }
    conv_us = std::min(conv_us, 1e6 * seconds_since(t0) / static_cast<double>(timed));
    t0 = Clock::now();
    for (std::size_t i = 0; i < timed; ++i) {
      sink += hyb_model.predict(rec.recognize(data[i].image).hybrid);
    }
    hyb_us = std::min(hyb_us, 1e6 * seconds_since(t0) / static_cast<double>(timed));
  }
  say("%-12s %11.1f us (%5.3f s) %11.1f us (%5.3f s)   [per image: features + decision]\n", "time",
      conv_us, 0.476, hyb_us, 0.502);
  volatile long long keep = sink;  // the timed work stays observable
  (void)keep;

  // Ablations of the edged/edgeless decision.
  t0 = Clock::now();
  bool truth = false;
  const tl::Dataset hyb_edgeless = hybrid_features(data, FixedDecision{}, nullptr, &truth);
  const tl::Dataset hyb_oracle = hybrid_features(data, FixedDecision{&truth}, &truth, &truth);
  const tl::CvReport edgeless_cv = cv_or_die(hyb_edgeless, false, opt.seed, "ablation: fold");
  const tl::CvReport oracle_cv = cv_or_die(hyb_oracle, false, opt.seed, "ablation: fold");
  say("\nHybrid with other edged/edgeless decisions (mean accuracy %%): paper's rule %.2f, "
      "RecEdgeless for every image %.2f, the true class's edgedness %.2f\n",
      100.0 * hyb_cv.accuracy, 100.0 * edgeless_cv.accuracy, 100.0 * oracle_cv.accuracy);

  // 4. Subject-grouped folds.
  const tl::CvReport conv_g = cv_or_die(conv, true, opt.seed, "grouped, conventional: fold");
  const tl::CvReport hyb_g = cv_or_die(hyb, true, opt.seed, "grouped, hybrid: fold");
  say("\nSubject-grouped 5-fold CV (no subject in training and test; the honest number for a new "
      "user):\n");
  say("%-12s %18s %18s\n", "class", "conventional", "hybrid");
  for (std::size_t k = 0; k < 4; ++k) {
    const int label = static_cast<int>(ts::kGraspClasses[k]);
    say("%-12s %18.2f %18.2f\n", std::string(ts::to_string(ts::kGraspClasses[k])).c_str(),
        percent_of_class(conv_g, label), percent_of_class(hyb_g, label));
  }
  say("%-12s %18.2f %18.2f\n", "mean", 100.0 * conv_g.accuracy, 100.0 * hyb_g.accuracy);

  // 5. Table 3: 5x2cv of LSVM against the competitors on the conventional features.
  say("\nTable 3: 5x2cv paired t test, reference LSVM, conventional features (z-scored)\n");
  say("%-22s %7s %7s %8s %7s %10s %10s %14s\n", "compared with", "err", "err ref", "t", "p",
      "H0 a=0.10", "H0 a=0.05", "paper t, H0");
  const auto row = [&](const char* name, const auto& other, double paper_t, const char* paper_h0) {
    tl::FiveByTwoOptions fo;
    fo.alpha = 0.10;
    fo.seed = opt.seed;
    fo.progress = progress_fn(name);
    fo.threads = g_threads;
    const tl::FiveByTwoResult r = tl::five_by_two_cv(other, make_lsvm(), conv.view(), fo);
    if (!r && r.status != taxel::Status::not_converged && r.status != taxel::Status::degenerate) {
      die(std::string("Table 3, ") + name + ": " + r.message);
    }
    const double crit05 = tl::student_t_quantile(0.975, 5.0);
    say("%-22s %6.2f%% %6.2f%% %8.3f %7.3f %10s %10s %7.3f %s\n", name, 100.0 * r.mean_error_a,
        100.0 * r.mean_error_b, r.t, r.p_value, r.reject ? "rejected" : "accepted",
        std::fabs(r.t) > crit05 ? "rejected" : "accepted", paper_t, paper_h0);
  };
  tl::MlpConfig mlp;
  mlp.hidden = {32};
  mlp.epochs = 100;
  row("FFNN (MLP 32 tanh)", tl::Scaled<tl::StandardScaler, tl::Mlp>(tl::Mlp(mlp)), 0.707,
      "accepted");
  row("kNN (k = 5)", tl::Scaled<tl::StandardScaler, tl::Knn>(), 1.414, "accepted");
  row("SVM-RBF (sigma = 1)",
      tl::Scaled<tl::StandardScaler, tl::RbfSvm>(tl::RbfSvm(tl::RbfSvmConfig::from_sigma(1.0))),
      1.238, "accepted");
  row("LDA", tl::Scaled<tl::StandardScaler, tl::Lda>(), 2.122, "rejected");
  say("(t = (error of the compared classifier - error of LSVM) in replication 1, fold 1, over the "
      "pooled\nspread; the paper's threshold 2.015 is alpha = 0.10 two-sided, Dietterich's 2.571 "
      "is 0.05)\n");

  // 6. Fig. 5: accuracy against feature SNR.
  const std::vector<double> snr = {
      std::numeric_limits<double>::infinity(), 50, 40, 30, 20, 10, 5, 0};
  auto folds = tl::kfold_assignment(conv.y, 5, opt.seed);
  if (!folds) die(folds.message);
  const SnrCurves conv_snr =
      accuracy_vs_snr(conv, folds.value, snr, opt.seed, "Fig. 5, conventional: fold");
  const SnrCurves hyb_snr =
      accuracy_vs_snr(hyb, folds.value, snr, opt.seed, "Fig. 5, hybrid: fold");
  say("\nFig. 5: accuracy %% against the SNR (dB) of white noise on the test features, awgn "
      "'measured'\nper vector, added to the standardised features (z-scored on the training "
      "folds) or to the raw ones\n");
  say("%-8s %14s %10s %16s %10s\n", "SNR", "z: conventional", "hybrid", "raw: conventional",
      "hybrid");
  taxel::io::LinePlot plot;
  plot.title = "Accuracy against feature SNR (synthetic palm grasps)";
  plot.x_label = "SNR of the test features (dB)";
  plot.y_label = "accuracy (%)";
  plot.reverse_x = true;
  plot.y_min = 0.0;
  plot.y_max = 100.0;
  plot.series = {{"conventional, standardised", {}, {}},
                 {"hybrid, standardised", {}, {}},
                 {"conventional, raw", {}, {}},
                 {"hybrid, raw", {}, {}}};
  for (std::size_t s = 0; s < snr.size(); ++s) {
    say("%-8s %15.2f %10.2f %17.2f %10.2f\n",
        std::isfinite(snr[s]) ? std::to_string(static_cast<int>(snr[s])).c_str() : "clean",
        conv_snr.standardised[s], hyb_snr.standardised[s], conv_snr.raw[s], hyb_snr.raw[s]);
    if (!std::isfinite(snr[s])) continue;
    const double* ys[] = {&conv_snr.standardised[s], &hyb_snr.standardised[s], &conv_snr.raw[s],
                          &hyb_snr.raw[s]};
    for (std::size_t k = 0; k < 4; ++k) {
      plot.series[k].x.push_back(snr[s]);
      plot.series[k].y.push_back(*ys[k]);
    }
  }
  const std::size_t at10 = 5;
  say("drop from clean to 10 dB: standardised: conventional %.2f, hybrid %.2f points; raw: "
      "conventional %.2f, hybrid %.2f points\n",
      conv_snr.standardised[0] - conv_snr.standardised[at10],
      hyb_snr.standardised[0] - hyb_snr.standardised[at10], conv_snr.raw[0] - conv_snr.raw[at10],
      hyb_snr.raw[0] - hyb_snr.raw[at10]);
  taxel::io::write_file((out / "accuracy_vs_snr.svg").string(), taxel::io::render_svg(plot));
  written.push_back((out / "accuracy_vs_snr.svg").string());

  // 7. Sample pictures: per class, image | segmentation | reconstruction for three subjects.
  std::vector<taxel::io::RgbImage> rows;
  for (ts::GraspClass c : ts::kGraspClasses) {
    std::vector<taxel::io::RgbImage> panels;
    for (int sid = 0; sid < 3; ++sid) {
      const ti::ImageD img = synth.render(synth.subject(sid), c, sid != 1, 0);
      const ti::Recognition& r = rec.recognize(img);
      if (!r.ok()) die("sample picture: " + r.message);
      const double hmax = std::max(1e-9, rec.reconstruction().maxCoeff());
      panels.push_back(
          taxel::io::side_by_side({taxel::io::colorize(img, 0, 255, 4),
                                   taxel::io::colorize_classes(rec.segmentation().classes, 4),
                                   taxel::io::colorize(rec.reconstruction(), 0, hmax, 4)},
                                  2));
    }
    rows.push_back(taxel::io::side_by_side(panels, 12));
  }
  write_picture(out / "samples", taxel::io::stacked(rows, 12), written);

  written.push_back((out / "report.txt").string());
  say("\nwrote (rows: planar, one-edged, two-edged, cylindrical; each panel image | k-means "
      "classes | reconstruction):\n");
  for (const auto& f : written) say("  %s\n", f.c_str());
  say("total %.1f s\n", seconds_since(start));
  taxel::io::write_file((out / "report.txt").string(), g_report);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "06_recognition_study: %s\n", e.what());
  return 1;
}
