// SPDX-License-Identifier: MIT
// taxel-icp: aligns a source cloud to a target cloud (both PLY) and prints the 4x4 transform
// T_target_source, the RMSE, the fitness (inlier fraction), the iterations and the status.
#include <charconv>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <taxel/io/ply.hpp>
#include <taxel/registration.hpp>
#include <vector>

#include "cli.hpp"
#include "report.hpp"

namespace {

namespace tr = taxel::registration;

constexpr const char* kUsage = R"usage(usage: taxel-icp [options] SOURCE.ply TARGET.ply

Aligns SOURCE to TARGET with ICP and prints T_target_source (4 rows of 4 numbers), then
"rmse", "fitness" (inlier fraction), "iterations" and "status" lines. The target's normals
come from its file or, when it has none, from PCA over its nearest neighbours. A TARGET with
faces (a mesh) stands for its surface: points drawn uniformly over it by area, about one per
--mesh-spacing squared, with the faces' normals (a line on standard error says so); SOURCE is
used as its vertices. Distances are in the files' unit (taxel uses metres).

options:
  --method point-to-plane|point-to-point   error (default point-to-plane)
  --kernel none|huber|cauchy|geman-mcclure|tukey   robust kernel (default none)
  --kernel-scale S      kernel width (default 0.001)
  --max-distance D      reject pairs farther apart than D (default: no limit)
  --trim F              drop the worst fraction F of pairs, [0, 1) (default 0)
  --max-iterations N    (default 50)
  --tolerance T         stop when an update moves less than T and turns less than T
                        radians (default 1e-6)
  --init "16 numbers"   initial T_target_source, row-major (default identity)
  --normal-neighbors K  neighbours of the PCA normals (default 12)
  --scale F             multiply both clouds' coordinates by F first (--scale 0.001 for files
                        in millimetres); the transform, distances and -o are then in metres
  --mesh-spacing D      sample a TARGET mesh at about one point per D^2 (default 0.001;
                        0: use its vertices only)
  -o FILE               also write the aligned source as PLY
  --format text|json|csv  how the result is printed (default text; json and csv give the
                        transform as 16 row-major numbers, its translation, rotation axis and
                        angle, and the same figures)
  -h, --help            show this help
  --version             show taxel's version

Lengths take a unit: 2mm, 0.2cm or 0.002 (metres). SOURCE or TARGET may be - for standard
input, and -o - writes the aligned source to standard output (the result then goes to standard
error).

Exit status: 0 when ICP ran (whatever its status), 1 for unreadable input, 2 for bad options.
)usage";

// Parses a number the way every option does (taxel_cli::Args::number), from a token.
double number(const taxel_cli::Args& args, std::string_view flag, std::string_view text) {
  double v = 0.0;
  const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
  if (res.ec != std::errc() || res.ptr != text.data() + text.size()) {
    args.fail(std::string(flag) + ": '" + std::string(text) + "' is not a number");
  }
  return v;
}

struct Options {
  bool point_to_point = false;
  std::string kernel = "none";
  double kernel_scale = 1e-3;
  tr::IcpConfig icp;
  taxel::Isometry3d init = taxel::Isometry3d::Identity();
  int normal_neighbors = 12;
  double scale = 1.0;
  double mesh_spacing = 1e-3;
  std::string output;
  taxel_cli::Format format = taxel_cli::Format::text;
  std::vector<std::string> inputs;
};

Options parse(taxel_cli::Args& args) {
  Options o;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--method") {
      const auto v = args.value();
      if (v != "point-to-plane" && v != "point-to-point") {
        args.fail("--method must be point-to-plane or point-to-point");
      }
      o.point_to_point = v == "point-to-point";
    } else if (a == "--kernel") {
      o.kernel = std::string(args.value());
      if (o.kernel != "none" && o.kernel != "huber" && o.kernel != "cauchy" &&
          o.kernel != "geman-mcclure" && o.kernel != "tukey") {
        args.fail("--kernel must be none, huber, cauchy, geman-mcclure or tukey");
      }
    } else if (a == "--kernel-scale") {
      o.kernel_scale = args.length(1e-300, kInf);
    } else if (a == "--max-distance") {
      o.icp.max_distance = args.length(-kInf, kInf);
    } else if (a == "--trim") {
      o.icp.trim_fraction = args.number<double>(-kInf, kInf);
    } else if (a == "--max-iterations") {
      o.icp.max_iterations = args.number<int>(1, 1000000);
    } else if (a == "--tolerance") {
      o.icp.translation_tolerance = o.icp.rotation_tolerance = args.number<double>(0.0, kInf);
    } else if (a == "--init") {
      const std::string_view v = args.value();
      std::vector<double> m;
      std::size_t p = 0;
      while (p < v.size()) {
        while (p < v.size() && (v[p] == ' ' || v[p] == ',' || v[p] == '\t')) ++p;
        std::size_t e = p;
        while (e < v.size() && v[e] != ' ' && v[e] != ',' && v[e] != '\t') ++e;
        if (e > p) m.push_back(number(args, a, v.substr(p, e - p)));
        p = e;
      }
      if (m.size() != 16) args.fail("--init needs 16 numbers, got " + std::to_string(m.size()));
      Eigen::Matrix4d t;
      for (int k = 0; k < 16; ++k) t(k / 4, k % 4) = m[static_cast<std::size_t>(k)];
      o.init.matrix() = t;
    } else if (a == "--normal-neighbors") {
      o.normal_neighbors = args.number<int>(3, 1000);
    } else if (a == "--scale") {
      o.scale = args.number<double>(1e-300, 1e300);
    } else if (a == "--mesh-spacing") {
      o.mesh_spacing = args.length(0.0, 1e300);
    } else if (a == "-o") {
      o.output = std::string(args.value());
    } else if (a == "--format") {
      o.format = taxel_cli::to_format(args.choice("text|json|csv"));
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.inputs.emplace_back(a);
    }
  }
  if (o.inputs.size() != 2) args.fail("expected SOURCE.ply and TARGET.ply (see --help)");
  if (o.inputs[0] == "-" && o.inputs[1] == "-") {
    args.fail("only one input can be standard input (-)");
  }
  return o;
}

template <class Error, class Kernel>
tr::IcpResult run(const Options& o, const tr::Target<double>& target,
                  const taxel::PointCloud<double>& source, Kernel kernel) {
  tr::Icp<Error, Kernel> icp(o.icp, kernel);
  return icp.align(target, source, o.init);
}

template <class Error>
tr::IcpResult dispatch(const Options& o, const tr::Target<double>& target,
                       const taxel::PointCloud<double>& source) {
  const double s = o.kernel_scale;
  if (o.kernel == "huber") return run<Error>(o, target, source, tr::Huber{s});
  if (o.kernel == "cauchy") return run<Error>(o, target, source, tr::Cauchy{s});
  if (o.kernel == "geman-mcclure") return run<Error>(o, target, source, tr::GemanMcClure{s});
  if (o.kernel == "tukey") return run<Error>(o, target, source, tr::Tukey{s});
  return run<Error>(o, target, source, tr::NoKernel{});
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-icp");
  taxel_cli::print_version_if_asked("taxel-icp", argc, argv);
  taxel_cli::Args args("taxel-icp", argc, argv);
  const Options opt = parse(args);
  args.check_output(opt.output, {opt.inputs[0], opt.inputs[1]});
  taxel::io::PlyData source, target;
  const std::string src_name = taxel_cli::input_name(opt.inputs[0]);
  const std::string tgt_name = taxel_cli::input_name(opt.inputs[1]);
  try {
    source = taxel::io::parse_ply(taxel_cli::read_input(opt.inputs[0]), src_name);
    target = taxel::io::parse_ply(taxel_cli::read_input(opt.inputs[1]), tgt_name);
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  for (auto* cloud : {&source.cloud, &target.cloud}) {
    if (opt.scale != 1.0) {
      for (auto& p : cloud->points) p *= opt.scale;
    }
  }
  taxel_cli::warn_if_millimetres("taxel-icp", src_name,
                                 taxel_cli::largest_extent(source.cloud.points));
  taxel_cli::warn_if_millimetres("taxel-icp", tgt_name,
                                 taxel_cli::largest_extent(target.cloud.points));
  tr::ModelCloud model;
  try {  // a mesh becomes its surface (after scaling: the spacing is in metres)
    model = tr::model_cloud(std::move(target), {.spacing = opt.mesh_spacing});
  } catch (const std::invalid_argument& e) {
    args.fail(tgt_name + ": " + e.what(), 1);
  }
  if (model.from_surface) {
    std::fprintf(stderr, "taxel-icp: %s: %s\n", tgt_name.c_str(), model.describe().c_str());
  }
  tr::IcpResult r;
  std::optional<tr::Target<double>> tg_storage;
  try {  // a model Target refuses (points too far apart to grid, bad normals) is bad data
    tg_storage.emplace(std::move(model.cloud),
                       tr::TargetConfig{.normal_neighbors = opt.normal_neighbors});
  } catch (const std::invalid_argument& e) {
    args.fail(tgt_name + ": " + e.what(), 1);
  }
  const tr::Target<double>& tg = *tg_storage;
  try {
    r = opt.point_to_point ? dispatch<tr::PointToPoint>(opt, tg, source.cloud)
                           : dispatch<tr::PointToPlane>(opt, tg, source.cloud);
  } catch (const std::invalid_argument& e) {  // a configuration Icp refuses
    args.fail(e.what());
  }
  std::string text;
  if (opt.format == taxel_cli::Format::text) {
    char line[160];
    for (int row = 0; row < 4; ++row) {
      std::snprintf(line, sizeof line, "%.17g %.17g %.17g %.17g\n", r.transform(row, 0),
                    r.transform(row, 1), r.transform(row, 2), r.transform(row, 3));
      text += line;
    }
    std::snprintf(line, sizeof line, "rmse %.9g\nfitness %.6f\niterations %d\nstatus %s\n", r.rmse,
                  r.inlier_fraction, r.iterations, std::string(taxel::to_string(r.status)).c_str());
    text += line;
  } else {
    taxel_cli::Json j = taxel_cli::pose_fields(r.transform);
    j["rmse"] = r.rmse;
    j["fitness"] = r.inlier_fraction;
    j["iterations"] = r.iterations;
    j["status"] = std::string(taxel::to_string(r.status));
    j["skipped"] = r.skipped;
    text = taxel_cli::render(j, opt.format);
  }
  std::fwrite(text.data(), 1, text.size(), opt.output == "-" ? stderr : stdout);
  if (!r.ok()) std::fprintf(stderr, "taxel-icp: %s\n", r.message.c_str());
  if (r.skipped > 0) {
    std::fprintf(stderr, "taxel-icp: %zu non-finite source points skipped\n", r.skipped);
  }
  if (!opt.output.empty()) {
    try {
      taxel_cli::write_output(opt.output,
                              taxel::io::encode_ply(taxel::transformed(source.cloud, r.transform)));
    } catch (const std::exception& e) {
      args.fail(e.what(), 1);
    }
  }
  return 0;
}
