// SPDX-License-Identifier: MIT
// taxel-predict: applies a LIBLINEAR-format linear model to a libsvm-format data set and writes
// one predicted label per line, with LIBLINEAR's `predict` output.
#include <charconv>
#include <cstdint>
#include <cstdio>
#include <exception>
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

constexpr const char* kUsage =
    R"usage(Usage: taxel-predict [options] test_file model_file output_file
options:
-q : quiet mode (no outputs)
--max-values n : largest dense data set read, samples x features (default 16777216)
--format text|json|csv : how the accuracy is printed (default text, as LIBLINEAR's predict;
	 json and csv give accuracy (a fraction), correct and total)
-h, --help : show this help
--version : show the version

model_file is a LIBLINEAR text model (from taxel-train or LIBLINEAR's train, any classification
solver). As LIBLINEAR does, features beyond the model's nr_feature are ignored. Prints
"Accuracy = x% (correct/total)" against the labels of test_file. -b (probability estimates)
is refused: LIBLINEAR gives them only for logistic-regression models.

Exit status: 0 on success, 1 for unreadable data or model (or an output that cannot be
written), 2 for bad options. Long options also take --name=value. test_file may be - for
standard input, output_file - for standard output (the accuracy then goes to standard error).
)usage";

// Bad options exit 2, bad data 1.
[[noreturn]] void fail(const std::string& why, int code = 1) {
  std::fprintf(stderr, "taxel-predict: %s\n", why.c_str());
  std::exit(code);
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-predict");
  taxel_cli::print_version_if_asked("taxel-predict", argc, argv);
  try {
    bool quiet = false;
    taxel_cli::Format format = taxel_cli::Format::text;
    std::vector<std::string> files;
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
        if (i + 1 >= argc) fail(std::string(a) + " needs a value", 2);
        return argv[++i];
      };
      if (a == "-h" || a == "--help") {
        std::fputs(kUsage, stdout);
        return 0;
      }
      if (a == "-q") {
        quiet = true;
      } else if (a == "--format") {
        const std::string_view v = value();
        if (v != "text" && v != "json" && v != "csv") {
          fail("--format must be one of text,json,csv, not '" + std::string(v) + "'", 2);
        }
        format = taxel_cli::to_format(v);
      } else if (a == "--max-values") {
        const std::string_view t = value();
        std::uint64_t v = 0;
        const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
        if (r.ec != std::errc{} || r.ptr != t.data() + t.size() || v == 0) {
          fail("--max-values expects a positive integer, got '" + std::string(t) + "'", 2);
        }
        read_opt.max_values = v;
      } else if (a == "-b") {
        fail(
            "-b (probability estimates) is not available: LIBLINEAR gives them only for "
            "logistic-regression models, and taxel's are SVMs",
            2);
      } else if (a.size() > 1 && a[0] == '-') {
        fail("unknown option '" + std::string(a) + "' (see --help)", 2);
      } else if (a.empty()) {
        fail("an argument is empty: name a file", 2);
      } else {
        files.emplace_back(a);
      }
      if (inline_value) fail(std::string(a) + " takes no value", 2);
    }
    if (files.size() != 3) {
      std::fputs(kUsage, stderr);
      return 2;
    }
    if (files[1] == "-") fail("model_file must be a file, not standard input", 2);
    if (const std::string why = taxel_cli::output_conflict(files[2], {files[0], files[1]});
        !why.empty()) {
      fail(why, 2);
    }
    const tl::LinearSvm model = tl::LinearSvm::load(taxel::io::read_file(files[1]), files[1]);
    tl::Dataset test = taxel::io::parse_libsvm(taxel_cli::read_input(files[0]),
                                               taxel_cli::input_name(files[0]), read_opt);
    if (test.dims() != model.dims()) {  // LIBLINEAR ignores extra features; absent ones are 0
      tl::FeatureMatrix x = tl::FeatureMatrix::Zero(test.rows(), model.dims());
      const Eigen::Index common = std::min(test.dims(), model.dims());
      x.leftCols(common) = test.x.leftCols(common);
      test.x = std::move(x);
    }
    std::string out;
    std::size_t correct = 0;
    for (Eigen::Index i = 0; i < test.rows(); ++i) {
      const int label = model.predict(test.x.row(i).transpose());
      correct += label == test.y[static_cast<std::size_t>(i)] ? 1 : 0;
      out.append(std::to_string(label)).append("\n");
    }
    taxel_cli::write_output(files[2], out);
    if (!quiet) {
      const auto total = static_cast<std::size_t>(test.rows());
      const double accuracy = static_cast<double>(correct) / static_cast<double>(total);
      std::string text;
      if (format == taxel_cli::Format::text) {
        char line[96];
        std::snprintf(line, sizeof line, "Accuracy = %g%% (%zu/%zu)\n", 100.0 * accuracy, correct,
                      total);
        text = line;
      } else {
        text = taxel_cli::render({{"accuracy", accuracy}, {"correct", correct}, {"total", total}},
                                 format);
      }
      std::fwrite(text.data(), 1, text.size(), files[2] == "-" ? stderr : stdout);
    }
    return 0;
  } catch (const std::exception& e) {
    fail(e.what());
  }
}
