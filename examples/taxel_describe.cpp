// SPDX-License-Identifier: MIT
// taxel-describe: pressure images (CSV, PGM, NPY; stacks too) in, the second paper's
// descriptors and features out, one line (CSV) or object (JSON) per frame.
#include <charconv>
#include <cstdio>
#include <exception>
#include <string>
#include <string_view>
#include <taxel/image.hpp>
#include <taxel/io.hpp>
#include <vector>

namespace {

namespace ti = taxel::image;

constexpr const char* kUsage = R"(usage: taxel-describe [options] IMAGE...

Describes pressure images as the second paper does: k-means segmentation, the union of the
high-pressure regions (HPRs), MATLAB-convention region descriptors, the 23 edged/edgeless
features, the edged decision and, with --hybrid, the 1035-long hybrid vector.
IMAGE is a .csv (one row per line), .pgm (P2/P5, 8/16 bit; several frames allowed) or .npy
(2-D image or 3-D stack of frames) file. One output record per frame.

options:
  --format csv|json     output format (default csv)
  --hybrid              also print the hybrid feature vector (rows*cols + 11 values)
  --polarity high|dark  which end of the scale is pressure (default high)
  --k N                 k-means clusters (default 3)
  --min-area N          HPR components below N pixels are removed (default 50)
  --threshold G         edged when the largest HPR's contour gradient exceeds G (default 25)
  --degree D            RecEdgeless polynomial degree (default 2)
  -o FILE               write to FILE instead of standard output
  -h, --help            show this help
)";

struct Options {
  bool json = false;
  bool hybrid = false;
  ti::RecognizerConfig cfg;
  double threshold = 25.0;
  std::string output;
  std::vector<std::string> inputs;
};

[[noreturn]] void die(const std::string& why) {
  std::fprintf(stderr, "taxel-describe: %s\n", why.c_str());
  std::exit(2);
}

template <class T>
T number(std::string_view flag, std::string_view text) {
  T v{};
  const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
  if (res.ec != std::errc() || res.ptr != text.data() + text.size()) {
    die(std::string(flag) + ": '" + std::string(text) + "' is not a valid number");
  }
  return v;
}

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    auto value = [&]() -> std::string_view {
      if (i + 1 >= argc) die(std::string(a) + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--format") {
      const auto v = value();
      if (v != "csv" && v != "json") die("--format must be csv or json");
      o.json = v == "json";
    } else if (a == "--hybrid") {
      o.hybrid = true;
    } else if (a == "--polarity") {
      const auto v = value();
      if (v != "high" && v != "dark") die("--polarity must be high or dark");
      o.cfg.segmentation.polarity =
          v == "high" ? ti::Polarity::high_is_pressure : ti::Polarity::dark_is_pressure;
    } else if (a == "--k") {
      o.cfg.segmentation.k = number<int>(a, value());
    } else if (a == "--min-area") {
      o.cfg.segmentation.min_area = number<int>(a, value());
    } else if (a == "--threshold") {
      o.threshold = number<double>(a, value());
    } else if (a == "--degree") {
      o.cfg.edgeless.degree = number<int>(a, value());
    } else if (a == "-o") {
      o.output = std::string(value());
    } else if (a.size() > 1 && a[0] == '-') {
      die("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.inputs.emplace_back(a);
    }
  }
  if (o.inputs.empty()) die("no input image (see --help)");
  return o;
}

std::string fmt(double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  return {buf, res.ptr};
}

std::string json_escape(std::string_view s) {
  std::string out;
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') out.push_back('\\');
    if (static_cast<unsigned char>(ch) < 0x20) {
      out += ' ';
      continue;
    }
    out.push_back(ch);
  }
  return out;
}

constexpr const char* kExtra[] = {"MajorAxisLength", "MinorAxisLength", "Solidity", "Extent",
                                  "EquivDiameter",   "EulerNumber4",    "Perimeter"};

}  // namespace

int main(int argc, char** argv) try {
  const Options opt = parse(argc, argv);
  std::FILE* out = stdout;
  if (!opt.output.empty()) {
    out = std::fopen(opt.output.c_str(), "w");
    if (out == nullptr) die("cannot open " + opt.output + " for writing");
  }
  if (!opt.json) {
    std::string header = "file,frame,status,edged,Gm";
    for (const auto name : ti::kEdgeFeatureNames) header += "," + std::string(name);
    for (const char* name : kExtra) header += std::string(",") + name;
    std::fprintf(out, "%s%s\n", header.c_str(), opt.hybrid ? ",hybrid..." : "");
  } else {
    std::fputs("[\n", out);
  }
  bool first = true;
  for (const std::string& path : opt.inputs) {
    const taxel::io::ImageStack stack = taxel::io::read_image(path);
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
        std::fprintf(out, "%s\n", line.c_str());
        continue;
      }
      std::string obj = first ? "  {" : ",\n  {";
      first = false;
      obj += "\"file\": \"" + json_escape(path) + "\", \"frame\": " + std::to_string(f) +
             ", \"status\": \"" + status + "\"";
      if (!r.ok()) obj += ", \"message\": \"" + json_escape(r.message) + "\"";
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
      std::fputs(obj.c_str(), out);
    }
  }
  if (opt.json) std::fputs("\n]\n", out);
  if (out != stdout && std::fclose(out) != 0) die("cannot write " + opt.output);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "taxel-describe: %s\n", e.what());
  return 1;
}
