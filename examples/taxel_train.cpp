// SPDX-License-Identifier: MIT
// taxel-train: trains a linear SVM on a libsvm-format data set, with LIBLINEAR's options,
// output and model file, so it can stand in for LIBLINEAR's `train` (-s 1 and -s 3).
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <taxel/io.hpp>
#include <taxel/learn.hpp>
#include <utility>

#include "cli.hpp"
#include "report.hpp"

namespace {

namespace tl = taxel::learn;

constexpr const char* kUsage = R"usage(Usage: taxel-train [options] training_set_file [model_file]
options:
-s type : set type of solver (default 1)
	 1 -- L2-regularized L2-loss support vector classification (dual)
	 3 -- L2-regularized L1-loss support vector classification (dual)
-c cost : set the parameter C (default 1)
-wi weight : weight of class i: its samples cost weight * C (default 1; e.g. -w1 5 -w-1 0.5)
-C : find the C with the best cross-validation accuracy (C = 2^k from 2^-10 up to 2^10, n
	 folds of -v or 5) and print "Best C = ... CV accuracy = ...%"; no model is written
-e epsilon : set tolerance of termination criterion (default 0.1)
	 |f'(alpha)|_max - |f'(alpha)|_min <= eps, the projected gradient spread
-B bias : if bias >= 0, instance x becomes [x; bias]; if < 0, no bias term added (default -1)
-v n: n-fold cross validation mode (stratified; prints Cross Validation Accuracy)
-q : quiet mode (no outputs)
--seed n : seed of the coordinate permutation and of the folds (default 1)
--grouped : with -v, keep each qid group in one fold
--max-iter n : outer iterations per binary problem (default 1000, as LIBLINEAR 2.3)
--max-values n : largest dense data set read, samples x features (default 16777216)
--format text|json|csv : how results are printed (default text, as LIBLINEAR's train; json
	 and csv give the cross-validation accuracy (a fraction), the -C grid, or per binary
	 problem the iterations, objective and support vectors)
-h, --help : show this help
--version : show the version

Exit status: 0 on success, 1 for unreadable or unusable data (and a model file that cannot be
written), 2 for bad options. -b (probability estimates) is refused: LIBLINEAR gives them only
for logistic regression, and taxel-train's solvers are SVMs.

Long options also take --name=value. training_set_file may be - for standard input, and
model_file - for standard output (what would be printed then goes to standard error).

The model file is LIBLINEAR's text format (default: <training_set_file basename>.model in the
current directory); LIBLINEAR's predict and taxel-predict both read it.
)usage";

// Bad options exit 2, bad data 1.
[[noreturn]] void fail(const std::string& why, int code = 1) {
  std::fprintf(stderr, "taxel-train: %s\n", why.c_str());
  std::exit(code);
}
[[noreturn]] void usage_error(const std::string& why) { fail(why, 2); }

double number(std::string_view opt, std::string_view t) {
  double v = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc{} || r.ptr != t.data() + t.size()) {
    usage_error("option " + std::string(opt) + " expects a number, got '" + std::string(t) + "'");
  }
  return v;
}

// An integer option's value in [lo, hi]: digits only (no fraction, no exponent), so that a
// value out of the option's type is refused, not converted.
template <class T>
T integer(std::string_view opt, std::string_view t, T lo, T hi, const char* what) {
  T v{};
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc{} || r.ptr != t.data() + t.size() || v < lo || v > hi) {
    usage_error(std::string(opt) + " expects " + what + ", got '" + std::string(t) + "'");
  }
  return v;
}

std::string basename(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-train");
  taxel_cli::print_version_if_asked("taxel-train", argc, argv);
  try {
    tl::LinearSvmConfig cfg;
    int folds = 0;
    bool quiet = false;
    bool grouped = false;
    bool search_c = false;
    std::string data_file;
    std::string model_file;
    taxel_cli::Format format = taxel_cli::Format::text;
    taxel::io::LibsvmReadOptions read_opt;
    for (int i = 1; i < argc; ++i) {
      std::string_view a = argv[i];
      std::optional<std::string_view> inline_value;  // --name=value
      if (a.starts_with("--") && a.find('=') != std::string_view::npos) {
        inline_value = a.substr(a.find('=') + 1);
        a = a.substr(0, a.find('='));
      }
      const auto value = [&]() -> std::string_view {
        if (inline_value) return *std::exchange(inline_value, std::nullopt);
        if (i + 1 >= argc) usage_error("option " + std::string(a) + " needs a value");
        return argv[++i];
      };
      if (a == "-h" || a == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      } else if (a == "-s") {
        const std::string_view t = value();
        const double s = number(a, t);
        if (s != 1.0 && s != 3.0)
          usage_error("-s " + std::string(t) +
                      " is not supported: taxel-train has solvers 1 (L2-loss) and 3 (L1-loss)");
        cfg.loss = s == 1.0 ? tl::SvmLoss::l2 : tl::SvmLoss::l1;
      } else if (a == "-c") {
        cfg.C = number(a, value());
      } else if (a == "-e") {
        cfg.eps = number(a, value());
      } else if (a == "-B") {
        cfg.bias = number(a, value());
      } else if (a == "-v") {
        folds = integer(a, value(), 2, 1 << 30, "the number of folds, an integer >= 2");
      } else if (a == "-q") {
        quiet = true;
      } else if (a == "--seed") {
        cfg.seed =
            integer(a, value(), std::uint64_t{0}, ~std::uint64_t{0}, "an integer in [0, 2^64)");
      } else if (a == "--max-iter") {
        cfg.max_iterations =
            integer(a, value(), 1, std::numeric_limits<int>::max(), "an integer in [1, 2^31)");
      } else if (a == "--max-values") {
        const double v = number(a, value());
        if (!(v >= 1.0 && v <= 1e18)) usage_error("--max-values must be in [1, 1e18]");
        read_opt.max_values = static_cast<std::uint64_t>(v);
      } else if (a == "--format") {
        const std::string_view v = value();
        if (v != "text" && v != "json" && v != "csv") {
          usage_error("--format must be one of text,json,csv, not '" + std::string(v) + "'");
        }
        format = taxel_cli::to_format(v);
      } else if (a == "--grouped") {
        grouped = true;
      } else if (a == "-C") {
        search_c = true;
      } else if (a == "-b") {
        usage_error(
            "-b (probability estimates) is not available: LIBLINEAR gives them only for "
            "logistic regression (-s 0, 6, 7), and taxel-train's solvers are SVMs (-s 1, 3)");
      } else if (a.size() > 2 && a.substr(0, 2) == "-w") {
        int label = 0;
        const std::string_view l = a.substr(2);
        const auto r = std::from_chars(l.data(), l.data() + l.size(), label);
        if (r.ec != std::errc{} || r.ptr != l.data() + l.size()) {
          usage_error("-w takes a class label glued to it (-w1 5, -w-1 0.5), got '" +
                      std::string(a) + "'");
        }
        cfg.class_weights.emplace_back(label, number(a, value()));
      } else if (a.size() > 1 && a[0] == '-') {
        usage_error("unknown option '" + std::string(a) + "' (see --help)");
      } else if (a.empty()) {
        usage_error("an argument is empty: name a file");
      } else if (data_file.empty()) {
        data_file = a;
      } else if (model_file.empty()) {
        model_file = a;
      } else {
        usage_error("too many arguments (see --help)");
      }
      if (inline_value) usage_error(std::string(a) + " takes no value");
    }
    if (data_file.empty()) {
      std::fputs(kUsage, stderr);
      return 2;
    }
    std::optional<tl::LinearSvm> checked;
    try {
      checked.emplace(cfg);  // validates the options
    } catch (const std::invalid_argument& e) {
      usage_error(e.what());
    }
    const tl::LinearSvm& prototype = *checked;
    if (const std::string why = taxel_cli::output_conflict(model_file, {data_file}); !why.empty()) {
      usage_error(why);
    }
    const tl::Dataset data = taxel::io::parse_libsvm(taxel_cli::read_input(data_file),
                                                     taxel_cli::input_name(data_file), read_opt);
    // A weight for a class the data does not have weighs nothing: say so, as LIBLINEAR does.
    for (const auto& [label, weight] : cfg.class_weights) {
      if (std::find(data.y.begin(), data.y.end(), label) == data.y.end()) {
        std::fprintf(stderr,
                     "taxel-train: warning: -w%d: %s has no class %d; the weight is unused\n",
                     label, taxel_cli::input_name(data_file).c_str(), label);
      }
    }
    if (data_file == "-" && model_file.empty() && !search_c && folds == 0) {
      usage_error(
          "with the training set on standard input, name the model_file (- for "
          "standard output)");
    }
    // Results go to standard output, or to standard error when the model goes there.
    FILE* const report_to = model_file == "-" ? stderr : stdout;
    const auto emit = [&](const std::string& text) {
      std::fwrite(text.data(), 1, text.size(), report_to);
    };

    if (search_c) {
      // LIBLINEAR's -C searches upwards from a small C with warm starts, for its primal
      // solvers only; here every C of the grid is cross-validated from scratch.
      tl::CvOptions opt;
      opt.folds = folds > 0 ? folds : 5;
      opt.seed = cfg.seed;
      opt.grouped = grouped;
      double best_c = 0.0, best_accuracy = -1.0;
      taxel_cli::Json grid = taxel_cli::Json::array();
      for (int e = -10; e <= 10; ++e) {
        tl::LinearSvmConfig c = cfg;
        c.C = std::ldexp(1.0, e);
        const tl::CvReport r = tl::cross_validate(tl::LinearSvm(c), data.view(), opt);
        if (r.status == taxel::Status::invalid_input || r.status == taxel::Status::degenerate) {
          fail(data_file + ": " + r.message);
        }
        if (!quiet && format == taxel_cli::Format::text) {
          std::fprintf(report_to, "log2c= %3d\trate= %g\n", e, 100.0 * r.accuracy);
        }
        grid.push_back({{"log2c", e}, {"C", c.C}, {"accuracy", r.accuracy}});
        if (r.accuracy > best_accuracy) {
          best_accuracy = r.accuracy;
          best_c = c.C;
        }
      }
      if (format == taxel_cli::Format::text) {
        std::fprintf(report_to, "Best C = %g  CV accuracy = %g%%\n", best_c, 100.0 * best_accuracy);
      } else if (format == taxel_cli::Format::json) {
        emit(taxel_cli::render({{"best_c", best_c},
                                {"accuracy", best_accuracy},
                                {"folds", opt.folds},
                                {"grid", std::move(grid)}},
                               format));
      } else {  // a row per C of the grid, the chosen one marked
        for (auto& row : grid) row["best"] = row["C"].get<double>() == best_c;
        emit(taxel_cli::render(grid, format));
      }
      return 0;
    }

    if (folds > 0) {
      tl::CvOptions opt;
      opt.folds = folds;
      opt.seed = cfg.seed;
      opt.grouped = grouped;
      if (!quiet && isatty(STDERR_FILENO) != 0) {
        opt.progress = [](std::size_t done, std::size_t total) {
          std::fprintf(stderr, "\rfold %zu/%zu%s", done, total, done == total ? "\n" : "");
        };
      }
      const tl::CvReport r = tl::cross_validate(prototype, data.view(), opt);
      if (r.status == taxel::Status::invalid_input || r.status == taxel::Status::degenerate) {
        fail(data_file + ": " + r.message);
      }
      if (!r.ok() && !quiet) std::fprintf(stderr, "taxel-train: warning: %s\n", r.message.c_str());
      if (format == taxel_cli::Format::text) {
        std::fprintf(report_to, "Cross Validation Accuracy = %g%%\n", 100.0 * r.accuracy);
      } else {
        emit(taxel_cli::render({{"folds", folds}, {"accuracy", r.accuracy}}, format));
      }
      return 0;
    }

    tl::LinearSvm model = prototype;
    const taxel::Outcome o = model.fit(data.view());
    if (o.status == taxel::Status::invalid_input || o.status == taxel::Status::degenerate) {
      fail(data_file + ": " + o.message);
    }
    if (model_file.empty()) model_file = basename(data_file) + ".model";
    taxel_cli::write_output(model_file, model.save());
    if (!quiet) {
      const tl::LinearSvmTrainInfo& info = model.info();
      taxel_cli::Json problems = taxel_cli::Json::array();
      for (std::size_t k = 0; k < info.iterations.size(); ++k) {
        if (format == taxel_cli::Format::text) {
          std::fprintf(report_to,
                       "optimization finished, #iter = %d\nObjective value = %f\nnSV = %d\n",
                       info.iterations[k], info.objective[k], info.support_vectors[k]);
        }
        problems.push_back({{"problem", k},
                            {"iterations", info.iterations[k]},
                            {"objective", info.objective[k]},
                            {"support_vectors", info.support_vectors[k]}});
      }
      if (format == taxel_cli::Format::json) {
        emit(taxel_cli::render({{"model_file", model_file == "-" ? "<stdout>" : model_file},
                                {"classes", model.classes()},
                                {"features", model.dims()},
                                {"problems", std::move(problems)}},
                               format));
      } else if (format == taxel_cli::Format::csv) {
        emit(taxel_cli::render(problems, format));
      }
      if (!o.ok()) std::fprintf(stderr, "taxel-train: warning: %s\n", o.message.c_str());
    }
    return 0;
  } catch (const std::exception& e) {
    fail(e.what());
  }
}
