// SPDX-License-Identifier: MIT
// taxel-recognize: ranks object models (PLY files, or every .ply in a folder) by how well a
// tactile cloud (PLY) aligns to each, by multi-start ICP (registration::ObjectLibrary).
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <taxel/io/ply.hpp>
#include <taxel/registration.hpp>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "report.hpp"

namespace {

namespace tr = taxel::registration;
namespace fs = std::filesystem;

constexpr const char* kUsage = R"usage(usage: taxel-recognize [options] CLOUD.ply MODEL...

Recognises the object a tactile cloud was taken from: every MODEL (a .ply file, or a folder
whose .ply files are all models; the name is the file name without .ply) is aligned to the
cloud from 28 starts (4 principal-axes, 24 cube rotations) and scored by the truncated RMS
distance of the cloud's points to it. Prints the ranking, best first, then the answer: the best
model's name, or "unknown" when even it scores above --unknown; then the best model's pose
T_model_cloud (which maps the cloud onto the model) as a 4x4 matrix, a translation and an
axis-angle rotation. Distances in metres. A PLY
with faces (a mesh) stands for its surface: points drawn uniformly over it by area, about one
per --mesh-spacing squared, so a finely and a coarsely meshed model weigh alike; one line on
standard error says so for each.

options:
  --unknown D        answer unknown above this score (default 0.003)
  --gate D           points farther than D count as D in the score (default 0.01)
  --starts N         cube-rotation starts, 0..24 (default 24)
  --threads N        share the starts out over N threads (default 0: every core; the answer
                     does not depend on N)
  --format text|json|csv  how the result is printed (default text; csv: a row per model,
                     best first, with its pose as translation, axis, angle and the 16 numbers
                     of the transform, row-major)
  --scale F          multiply the cloud's and the models' coordinates by F first
                     (--scale 0.001 for files in millimetres)
  --mesh-spacing D   sample meshes at about one point per D^2 (default 0.001; 0: use
                     their vertices only)
  -h, --help         show this help
  --version          show taxel's version

Lengths take a unit: 3mm, 0.3cm or 0.003 (metres). CLOUD may be - for standard input.

Exit status: 0 when the cloud was ranked, 1 for unreadable input, 2 for bad options.
)usage";

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-recognize");
  taxel_cli::print_version_if_asked("taxel-recognize", argc, argv);
  taxel_cli::Args args("taxel-recognize", argc, argv);
  const auto die = [&](const std::string& why, int code = 2) { args.fail(why, code); };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  tr::LibraryConfig cfg;
  taxel_cli::Format format = taxel_cli::Format::text;
  double scale = 1.0;
  tr::ModelSampling sampling;
  std::vector<std::string> inputs;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--unknown") {
      cfg.unknown_score = args.length(-kInf, kInf);
    } else if (a == "--gate") {
      cfg.score_gate = args.length(-kInf, kInf);
    } else if (a == "--starts") {
      cfg.rotation_starts = args.number<int>(-1000, 1000);
    } else if (a == "--threads") {
      cfg.threads = args.number<unsigned>(0, 4096);
    } else if (a == "--scale") {
      scale = args.number<double>(1e-300, 1e300);
    } else if (a == "--mesh-spacing") {
      sampling.spacing = args.length(0.0, 1e300);
    } else if (a == "--format") {
      format = taxel_cli::to_format(args.choice("text|json|csv"));
    } else if (a.size() > 1 && a[0] == '-') {
      die("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      inputs.emplace_back(a);
    }
  }
  if (inputs.size() < 2) die("expected CLOUD.ply and at least one MODEL (see --help)");
  for (std::size_t k = 1; k < inputs.size(); ++k) {
    if (inputs[k] == "-") die("only CLOUD can be standard input (-); the models are files");
  }

  std::vector<fs::path> models;
  for (std::size_t k = 1; k < inputs.size(); ++k) {
    const fs::path p(inputs[k]);
    std::error_code ec;
    if (fs::is_directory(p, ec)) {
      std::vector<fs::path> found;
      for (const auto& e : fs::directory_iterator(p, ec)) {
        if (e.is_regular_file() && e.path().extension() == ".ply") found.push_back(e.path());
      }
      if (found.empty()) die(p.string() + ": no .ply files in this folder", 1);
      std::sort(found.begin(), found.end());
      models.insert(models.end(), found.begin(), found.end());
    } else {
      models.push_back(p);
    }
  }

  tr::ObjectRecognition r;
  std::optional<tr::ObjectLibrary<double>> lib;
  try {
    lib.emplace(cfg);
  } catch (const std::invalid_argument& e) {  // the options
    die(e.what(), 2);
  }
  try {
    // Scaled, and checked for millimetres (a tactile object spans centimetres).
    // Meshes become their surface (after scaling: the spacing is in metres).
    const auto load = [&](const std::string& file) {
      const std::string path = taxel_cli::input_name(file);
      taxel::io::PlyData ply = taxel::io::parse_ply(taxel_cli::read_input(file), path);
      if (scale != 1.0) {
        for (auto& p : ply.cloud.points) p *= scale;
      }
      taxel_cli::warn_if_millimetres("taxel-recognize", path,
                                     taxel_cli::largest_extent(ply.cloud.points));
      tr::ModelCloud m;
      try {
        m = tr::model_cloud(std::move(ply), sampling);
      } catch (const std::invalid_argument& e) {
        die(path + ": " + e.what(), 1);
      }
      if (m.from_surface)
        std::fprintf(stderr, "taxel-recognize: %s: %s\n", path.c_str(), m.describe().c_str());
      return std::move(m.cloud);
    };
    for (const auto& m : models) {
      try {
        lib->add(m.stem().string(), load(m.string()));
      } catch (const std::invalid_argument& e) {  // a model the library refuses: bad data
        die(m.string() + ": " + e.what(), 1);
      }
    }
    r = lib->recognize(load(inputs[0]));
  } catch (const taxel::IoError& e) {
    die(e.what(), 1);
  }
  if (!r.ok()) die(taxel_cli::input_name(inputs[0]) + ": " + r.message, 1);

  if (format != taxel_cli::Format::text) {
    // JSON: the answer and the ranking; CSV: a row per model, with the answer in each row.
    taxel_cli::Json ranking = taxel_cli::Json::array();
    for (std::size_t k = 0; k < r.ranking.size(); ++k) {
      const auto& m = r.ranking[k];
      taxel_cli::Json row = {{"rank", k + 1},    {"model", m.name}, {"score", m.score},
                             {"exact", m.exact}, {"rmse", m.rmse},  {"fitness", m.inlier_fraction}};
      row.update(taxel_cli::pose_fields(m.transform));
      ranking.push_back(std::move(row));
    }
    std::string text;
    if (format == taxel_cli::Format::json) {
      text = taxel_cli::render({{"best", r.best},
                                {"unknown", r.unknown},
                                {"margin", r.margin},
                                {"ranking", std::move(ranking)}},
                               format);
    } else {
      for (auto& row : ranking) {
        row["best"] = r.best;
        row["unknown"] = r.unknown;
        row["margin"] = r.margin;
      }
      text = taxel_cli::render(ranking, format);
    }
    std::fwrite(text.data(), 1, text.size(), stdout);
    return 0;
  }
  // T_model_cloud as translation [m] and axis-angle (unit axis, angle [rad]).
  const auto axis_angle = [](const taxel::Isometry3d& t) {
    const Eigen::AngleAxisd aa(t.linear());
    return std::pair<taxel::Vec3d, double>(aa.angle() > 0.0 ? aa.axis() : taxel::Vec3d::UnitZ(),
                                           aa.angle());
  };
  std::printf("%-4s %-32s %10s %10s %8s\n", "rank", "model", "score_mm", "rmse_mm", "fitness");
  for (std::size_t k = 0; k < r.ranking.size(); ++k) {
    const auto& m = r.ranking[k];
    if (m.exact) {
      std::printf("%-4zu %-32s %10.3f %10.3f %8.3f\n", k + 1, m.name.c_str(), 1e3 * m.score,
                  1e3 * m.rmse, m.inlier_fraction);
    } else {
      std::printf("%-4zu %-32s %10.3f %10s %8s\n", k + 1, m.name.c_str(), 1e3 * m.score, "-", "-");
    }
  }
  std::printf("best: %s (margin %.3f mm)\n", r.best.c_str(), 1e3 * r.margin);
  // The pose of the best-scoring model (also when the answer is unknown): T_model_cloud maps
  // the cloud's points onto the model.
  const auto& top = r.ranking.front();
  const auto [axis, angle] = axis_angle(top.transform);
  const taxel::Vec3d t = top.transform.translation();
  std::printf("pose of %s (T_model_cloud):\n", top.name.c_str());
  for (int row = 0; row < 4; ++row) {
    std::printf("%.9g %.9g %.9g %.9g\n", top.transform(row, 0), top.transform(row, 1),
                top.transform(row, 2), top.transform(row, 3));
  }
  std::printf("translation %.9g %.9g %.9g\naxis %.9g %.9g %.9g\nangle %.9g rad (%.3f deg)\n", t.x(),
              t.y(), t.z(), axis.x(), axis.y(), axis.z(), angle, angle * 180.0 / std::numbers::pi);
  return 0;
}
