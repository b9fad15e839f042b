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
  --format csv|json|libsvm  output format (default csv)
  --labels FILE         one integer label per frame, first token of each line ('#' comments
                        and blank lines skipped); required by --format libsvm
  --hybrid              also print the hybrid feature vector (rows*cols + 11 values)
  --polarity high|dark  which end of the scale is pressure (default high)
  --k N                 k-means clusters (default 3)
  --min-area N          HPR components below N pixels are removed (default 50)
  --threshold G         edged when the largest HPR's contour gradient exceeds G (default 25)
  --degree D            RecEdgeless polynomial degree (default 2)
  -o FILE               write to FILE instead of standard output
  -h, --help            show this help
  --version             show taxel's version
)";

struct Options {
  bool json = false;
  bool libsvm = false;
  std::string labels;
  bool hybrid = false;
  ti::RecognizerConfig cfg;
  double threshold = 25.0;
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
      const auto v = value();
      if (v != "csv" && v != "json" && v != "libsvm") die("--format must be csv, json or libsvm");
      o.json = v == "json";
      o.libsvm = v == "libsvm";
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
      o.cfg.segmentation.k =
          args.number<int>(std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
    } else if (a == "--min-area") {
      o.cfg.segmentation.min_area =
          args.number<int>(std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
    } else if (a == "--threshold") {
      o.threshold = args.number<double>(-std::numeric_limits<double>::infinity(),
                                        std::numeric_limits<double>::infinity());
    } else if (a == "--degree") {
      o.cfg.edgeless.degree =
          args.number<int>(std::numeric_limits<int>::min(), std::numeric_limits<int>::max());
    } else if (a == "-o") {
      o.output = std::string(value());
    } else if (a.size() > 1 && a[0] == '-') {
      die("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.inputs.emplace_back(a);
    }
  }
  if (o.inputs.empty()) die("no input image (see --help)");
  if (o.libsvm && o.labels.empty()) die("--format libsvm needs --labels FILE");
  if (!o.libsvm && !o.labels.empty()) die("--labels is only used with --format libsvm");
  return o;
}

std::string fmt(double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return {buf, res.ptr};
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

// An image file: .png through libpng when built with it, the rest by io::read_image.
taxel::io::ImageStack load_image(const std::string& path) {
  if (taxel::io::extension(path) == ".png") {
#ifdef TAXEL_DESCRIBE_HAVE_PNG
    return taxel::io::read_png_image(path);
#else
    throw taxel::IoError(path, "PNG input needs taxel-describe built with libpng");
#endif
  }
  return taxel::io::read_image(path);
}

// --format libsvm: every frame's features with its label.
std::string describe_libsvm(const Options& opt) {
  const std::vector<int> labels = read_labels(opt.labels);
  taxel::learn::Dataset d;
  std::vector<Eigen::VectorXd> rows;
  for (const std::string& path : opt.inputs) {
    const taxel::io::ImageStack stack = load_image(path);
    ti::Recognizer<> rec(stack.rows, stack.cols, opt.cfg, ti::GradientThreshold{opt.threshold});
    for (Eigen::Index f = 0; f < stack.frames; ++f) {
      const ti::Recognition& r = rec.recognize(stack.frame(f));
      if (!r.ok()) {
        bad_data(path + " frame " + std::to_string(f) + ": " +
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
  } else if (!opt.json) {
    out = "file,frame,status,edged,Gm";
    for (const auto name : ti::kEdgeFeatureNames) out += "," + std::string(name);
    for (const char* name : kExtra) out += std::string(",") + name;
    out += opt.hybrid ? ",hybrid...\n" : "\n";
  } else {
    out = "[\n";
  }
  bool first = true;
  for (const std::string& path : opt.libsvm ? std::vector<std::string>{} : opt.inputs) {
    const taxel::io::ImageStack stack = load_image(path);
    ti::Recognizer<> rec(stack.rows, stack.cols, opt.cfg, ti::GradientThreshold{opt.threshold});
    ti::RegionAnalyzer props({}, stack.rows, stack.cols);
    for (Eigen::Index f = 0; f < stack.frames; ++f) {
      const ti::Recognition& r = rec.recognize(stack.frame(f));
      const ti::RegionProps& p = props.compute(rec.segmentation().high);
      const double extra[] = {p.major_axis, p.minor_axis,     p.solidity,
                              p.extent,     p.equiv_diameter, static_cast<double>(p.euler_number4),
                              p.perimeter};
      std::string status(taxel::to_string(r.status));
      if (!opt.json) {
        std::string line = path + "," + std::to_string(f) + "," + status + "," +
                           (r.edged ? "1" : "0") + "," + fmt(r.contour_gradient);
        for (Eigen::Index i = 0; i < r.edge_features.size(); ++i) {
          line += "," + fmt(r.edge_features(i));
        }
        for (double v : extra) line += "," + fmt(v);
        if (opt.hybrid) {
          for (Eigen::Index i = 0; i < r.hybrid.size(); ++i) line += "," + fmt(r.hybrid(i));
        }
        out.append(line).append("\n");
        continue;
      }
      std::string obj = first ? "  {" : ",\n  {";
      first = false;
      obj += "\"file\": \"" + taxel_cli::json_escape(path) + "\", \"frame\": " + std::to_string(f) +
             ", \"status\": \"" + status + "\"";
      if (!r.ok()) obj += ", \"message\": \"" + taxel_cli::json_escape(r.message) + "\"";
      obj += std::string(", \"edged\": ") + (r.edged ? "true" : "false") +
             ", \"Gm\": " + fmt(r.contour_gradient) + ", \"features\": {";
      for (std::size_t i = 0; i < ti::kEdgeFeatureNames.size(); ++i) {
        obj += (i ? ", \"" : "\"") + std::string(ti::kEdgeFeatureNames[i]) +
               "\": " + fmt(r.edge_features(static_cast<Eigen::Index>(i)));
      }
      for (std::size_t i = 0; i < std::size(kExtra); ++i) {
        obj += std::string(", \"") + kExtra[i] + "\": " + fmt(extra[i]);
      }
      obj += "}";
      if (opt.hybrid) {
        obj += ", \"hybrid\": [";
        for (Eigen::Index i = 0; i < r.hybrid.size(); ++i)
          obj += (i ? ", " : "") + fmt(r.hybrid(i));
        obj += "]";
      }
      obj += "}";
      out += obj;
    }
  }
  if (opt.json && !opt.libsvm) out += "\n]\n";
  if (opt.output.empty()) {
    std::fwrite(out.data(), 1, out.size(), stdout);  // checked at exit
  } else {
    taxel::io::write_file(opt.output, out);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "taxel-describe: %s\n", e.what());
  return 1;
}
