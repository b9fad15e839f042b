// SPDX-License-Identifier: MIT
// taxel-describe: pressure images (CSV, PGM, NPY; stacks too) in, the second paper's
// descriptors and features out, one line (CSV) or object (JSON) per frame.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <string_view>
#include <taxel/image.hpp>
#include <taxel/io.hpp>
#include <taxel/learn/dataset.hpp>
#include <vector>

#ifdef TAXEL_DESCRIBE_HAVE_PNG
#include <taxel/io/png.hpp>
#endif

#include "cli.hpp"
#include "report.hpp"

namespace {

namespace ti = taxel::image;

constexpr const char* kUsage = R"(usage: taxel-describe [options] IMAGE...

Describes pressure images as the second paper does: k-means segmentation, the union of the
high-pressure regions (HPRs), MATLAB-convention region descriptors, the 23 edged/edgeless
features, the edged decision and, with --hybrid, the 1035-long hybrid vector.
IMAGE is a .csv or .txt (one row per line, values separated by commas or, as numpy's
np.savetxt writes them, by spaces), .pgm (P2/P5, 8/16 bit; several frames allowed), .png
(greyscale, 8/16 bit, the samples as stored) or .npy (2-D image or 3-D stack of frames) file. One output record per frame.

With --format libsvm the output is a training file for taxel-train (or LIBLINEAR): one line
per frame, its label from --labels, then the 11 regional features (conventional recognition)
or, with --hybrid, the 1035-long hybrid vector.

options:
  --format csv|json|text|libsvm  output format (default csv; text: "name value" lines per
                        frame, frames separated by a blank line)
  --labels FILE         one integer label per frame, first token of each line ('#' comments
                        and blank lines skipped); required by --format libsvm
  --hybrid              also print the hybrid feature vector (rows*cols + 11 values)
  --polarity high|dark  which end of the scale is pressure (default high)
  --k N                 k-means clusters (default 3)
  --min-area N          HPR components below N pixels are removed (default 50)
  --threshold G         edged when the largest HPR's contour gradient exceeds G (default 25)
  --degree D            RecEdgeless polynomial degree (default 2)
  --threads N           describe the frames of a stack on N threads for --format libsvm
                        (default 0: every core; the output does not depend on N)
  -o FILE               write to FILE instead of standard output
  -h, --help            show this help
  --version             show taxel's version

IMAGE may be - for standard input; its format is then told by its first bytes (NPY, PGM,
PNG, else text). Nothing is written unless every frame was read and described.
)";

struct Options {
  taxel_cli::Format format = taxel_cli::Format::csv;
  bool libsvm = false;
  std::string labels;
  bool hybrid = false;
  ti::RecognizerConfig cfg;
  double threshold = 25.0;
  unsigned threads = 0;
  std::string output;
  std::vector<std::string> inputs;
};

// Bad options exit 2, bad or unwritable data 1; nothing has been written yet either way.
[[noreturn]] void die(const std::string& why, int code = 2) {
  std::fprintf(stderr, "taxel-describe: %s\n", why.c_str());
  std::exit(code);
}
[[noreturn]] void bad_data(const std::string& why) { die(why, 1); }

Options parse(int argc, char** argv) {
  taxel_cli::Args args("taxel-describe", argc, argv);
  const auto value = [&] { return args.value(); };
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--format") {
      const auto v = args.choice("csv|json|text|libsvm");
      o.libsvm = v == "libsvm";
      if (!o.libsvm) o.format = taxel_cli::to_format(v);
    } else if (a == "--labels") {
      o.labels = std::string(value());
    } else if (a == "--hybrid") {
      o.hybrid = true;
    } else if (a == "--polarity") {
      const auto v = value();
      if (v != "high" && v != "dark") die("--polarity must be high or dark");
      o.cfg.segmentation.polarity =
          v == "high" ? ti::Polarity::high_is_pressure : ti::Polarity::dark_is_pressure;
    } else if (a == "--k") {
      o.cfg.segmentation.k = args.number<int>(2, 255);  // SegmentationConfig's range
    } else if (a == "--min-area") {
      o.cfg.segmentation.min_area = args.number<int>(0, std::numeric_limits<int>::max());
    } else if (a == "--threshold") {
      o.threshold = args.number<double>(-std::numeric_limits<double>::infinity(),
                                        std::numeric_limits<double>::infinity());
    } else if (a == "--degree") {
      o.cfg.edgeless.degree = args.number<int>(0, 6);  // RecEdgelessConfig's range
    } else if (a == "--threads") {
      o.threads = args.number<unsigned>(0, 4096);
    } else if (a == "-o") {
      o.output = std::string(value());
    } else if (a.size() > 1 && a[0] == '-') {
      die("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.inputs.emplace_back(a);
    }
  }
  if (o.inputs.empty()) die("no input image (see --help)");
  if (std::count(o.inputs.begin(), o.inputs.end(), "-") > 1) {
    die("only one input can be standard input (-)");
  }
  if (o.libsvm && o.labels.empty()) die("--format libsvm needs --labels FILE");
  if (!o.libsvm && !o.labels.empty()) die("--labels is only used with --format libsvm");
  std::vector<std::string> read = o.inputs;
  read.push_back(o.labels);
  if (const std::string why = taxel_cli::output_conflict(o.output, read); !why.empty()) die(why);
  return o;
}

constexpr const char* kExtra[] = {"MajorAxisLength", "MinorAxisLength", "Solidity", "Extent",
                                  "EquivDiameter",   "EulerNumber4",    "Perimeter"};

// Labels: the first token of each non-blank, non-comment line, an integer.
std::vector<int> read_labels(const std::string& path) {
  const std::string text = taxel::io::read_file(path);
  std::vector<int> labels;
  std::size_t line_no = 0;
  for (std::size_t pos = 0; pos < text.size();) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string_view::npos || line[first] == '#') continue;
    line.remove_prefix(first);
    const auto stop = std::min(line.find_first_of(" \t\r,"), line.size());
    const std::string_view token = line.substr(0, stop);
    int v = 0;
    const auto res = std::from_chars(token.data(), token.data() + token.size(), v);
    if (res.ec != std::errc() || res.ptr != token.data() + token.size()) {
      bad_data(path + ":" + std::to_string(line_no) + ": '" + std::string(token.substr(0, 20)) +
               "' is not an integer label");
    }
    labels.push_back(v);
  }
  return labels;
}

// An image file: .png through libpng when built with it, the rest by io::read_image; standard
// input ("-") by its first bytes.
taxel::io::ImageStack load_image(const std::string& path) {
  std::string ext = taxel::io::extension(path);
  std::string bytes;
  if (path == "-") {
    bytes = taxel_cli::read_input(path);
    const std::string_view b(bytes);
    ext = b.starts_with("\x93NUMPY")                   ? ".npy"
          : b.starts_with("P2") || b.starts_with("P5") ? ".pgm"
          : b.starts_with("\x89PNG")                   ? ".png"
                                                       : ".csv";
  }
  const std::string name = taxel_cli::input_name(path);
  if (ext == ".png") {
#ifdef TAXEL_DESCRIBE_HAVE_PNG
    if (path == "-") return taxel::io::decode_png_image(bytes, name);
    return taxel::io::read_png_image(path);
#else
    throw taxel::IoError(name, "PNG input needs taxel-describe built with libpng");
#endif
  }
  if (path != "-") return taxel::io::read_image(path);
  if (ext == ".npy") return taxel::io::parse_npy(bytes, name);
  if (ext == ".pgm") return taxel::io::parse_pgm(bytes, name);
  return taxel::io::parse_image_csv(bytes, name);
}

// --format libsvm: every frame's features with its label.
std::string describe_libsvm(const Options& opt) {
  const std::vector<int> labels = read_labels(opt.labels);
  taxel::learn::Dataset d;
  std::vector<Eigen::VectorXd> rows;
  for (const std::string& path : opt.inputs) {
    const taxel::io::ImageStack stack = load_image(path);
    const ti::Recognizer<> rec(stack.rows, stack.cols, opt.cfg,
                               ti::GradientThreshold{opt.threshold});
    const std::vector<ti::Recognition> described = ti::recognize_all(
        rec, static_cast<std::size_t>(stack.frames),
        [&](std::size_t f) { return stack.frame(static_cast<Eigen::Index>(f)); }, opt.threads);
    for (Eigen::Index f = 0; f < stack.frames; ++f) {
      const ti::Recognition& r = described[static_cast<std::size_t>(f)];
      if (!r.ok()) {
        bad_data(taxel_cli::input_name(path) + " frame " + std::to_string(f) + ": " +
                 std::string(taxel::to_string(r.status)) + ": " + r.message);
      }
      rows.push_back(opt.hybrid ? r.hybrid : r.regional);
    }
  }
  if (labels.size() != rows.size()) {
    bad_data(opt.labels + " has " + std::to_string(labels.size()) + " labels for " +
             std::to_string(rows.size()) + " frames");
  }
  d.x.resize(static_cast<Eigen::Index>(rows.size()), rows.empty() ? 0 : rows.front().size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    if (rows[i].size() != d.x.cols()) bad_data("the input images differ in size");
    d.x.row(static_cast<Eigen::Index>(i)) = rows[i].transpose();
  }
  d.y = labels;
  return taxel::io::encode_libsvm(d.view());
}

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("taxel-describe");
  taxel_cli::print_version_if_asked("taxel-describe", argc, argv);
  const Options opt = parse(argc, argv);
  // The whole output is built first and written once: a failure leaves no partial output.
  std::string out;
  if (opt.libsvm) {
    out = describe_libsvm(opt);
  } else {
    taxel_cli::Json records = taxel_cli::Json::array();
    for (const std::string& path : opt.inputs) {
      const taxel::io::ImageStack stack = load_image(path);
      ti::Recognizer<> rec(stack.rows, stack.cols, opt.cfg, ti::GradientThreshold{opt.threshold});
      ti::RegionAnalyzer props({}, stack.rows, stack.cols);
      for (Eigen::Index f = 0; f < stack.frames; ++f) {
        const ti::Recognition& r = rec.recognize(stack.frame(f));
        const ti::RegionProps& p = props.compute(rec.segmentation().high);
        const double extra[] = {p.major_axis,     p.minor_axis,
                                p.solidity,       p.extent,
                                p.equiv_diameter, static_cast<double>(p.euler_number4),
                                p.perimeter};
        taxel_cli::Json row = {{"file", taxel_cli::input_name(path)},
                               {"frame", f},
                               {"status", std::string(taxel::to_string(r.status))}};
        if (opt.format == taxel_cli::Format::json && !r.ok()) row["message"] = r.message;
        row["edged"] = opt.format == taxel_cli::Format::csv ? taxel_cli::Json(r.edged ? 1 : 0)
                                                            : taxel_cli::Json(r.edged);
        row["Gm"] = r.contour_gradient;
        taxel_cli::Json features = taxel_cli::Json::object();
        for (std::size_t i = 0; i < ti::kEdgeFeatureNames.size(); ++i) {
          features[std::string(ti::kEdgeFeatureNames[i])] =
              r.edge_features(static_cast<Eigen::Index>(i));
        }
        for (std::size_t i = 0; i < std::size(kExtra); ++i) features[kExtra[i]] = extra[i];
        if (opt.format == taxel_cli::Format::json) {
          row["features"] = std::move(features);
        } else {  // flat columns, as the CSV header has always named them
          row.update(features);
        }
        if (opt.hybrid) {
          row["hybrid"] = std::vector<double>(r.hybrid.data(), r.hybrid.data() + r.hybrid.size());
        }
        records.push_back(std::move(row));
      }
    }
    out = taxel_cli::render(records, opt.format);
  }
  if (opt.output.empty() || opt.output == "-") {
    std::fwrite(out.data(), 1, out.size(), stdout);  // checked at exit
  } else {
    taxel::io::write_file(opt.output, out);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "taxel-describe: %s\n", e.what());
  return 1;
}
