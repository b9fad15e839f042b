// SPDX-License-Identifier: MIT
// taxel-explore: simulated active touch. A pad pokes a simulated object along approach rays
// chosen by a policy; the touches are fused into a Gaussian-process implicit surface, and
// after every touch the tool prints how close the estimate is to the truth, how much of the
// surface was touched and how sure the estimate is; with a library of models, which object it
// is and how probable.
#include <cstdio>
#include <exception>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <taxel/io/ply.hpp>
#include <taxel/registration.hpp>
#include <taxel/sim.hpp>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "explore_harness.hpp"
#include "report.hpp"
#include "sim_shapes.hpp"

namespace {

namespace ts = taxel::sim;
namespace tr = taxel::registration;
namespace fs = std::filesystem;

constexpr const char* kUsage = R"usage(usage: taxel-explore [options]

Explores a simulated object by touch and prints, after each touch, the estimate's quality.
The object is placed at a random orientation near the origin (from --seed). Each touch is an
approach ray: the pad (a 14x6 matrix at 3.4 mm) follows it to the object, presses 1 mm in with
its face tangent to the surface and lets go. Its contacts are fused (Surfel) into a
Gaussian-process implicit surface with local experts (Matern 3/2 kernel), meshed every touch.

Per touch: the contacts so far; surface_rms, the symmetric RMS distance between the estimate's
mesh and the true surface (both ways) [m]; surface_signed, the mean signed distance of the
estimate to the true surface [m] (> 0: the estimate lies outside); coverage, the share of the true surface within
--coverage-radius of a fused point; mean_std, the estimate's posterior standard deviation
averaged over its area [m]. With --library, also top1 (the most probable model's file name
without .ply) and its probability.

options:
  --shape sphere|cylinder|box|cone|ellipsoid|torus   the object (default sphere)
  --size A[,B[,C]]   its dimensions, as taxel-simulate takes them
  --mesh FILE.ply    explore this closed triangle mesh (metres) instead of --shape
  --policy active|random|scripted   how the next touch is chosen (default active):
                     active: of --candidates random approach rays, the one whose predicted
                     contact most lowers the surface's variance (with --library: first the
                     one that best tells the likely models apart); random: a random ray;
                     scripted: rays from evenly spread directions, in a fixed order
  --touches N        touches (default 40)
  --candidates N     approach rays drawn per touch (default 200)
  --seed S           object pose, rays and sensor noise (default 1)
  --library DIR      recognise the object among the models in DIR (every .ply file, meshes
                     or point clouds in metres)
  --grid D           spacing of the estimate's field and mesh (default 3mm)
  --coverage-radius D   (default 5mm)
  --out DIR          write the estimate after touch k as DIR/touch_<k>.ply: a mesh whose
                     vertices carry their posterior standard deviation as the property sigma
  --format text|json|csv   how the table is printed (default text)
  -h, --help         show this help
  --version          show taxel's version

Lengths take a unit: 3mm, 0.3cm or 0.003 (metres).

Exit status: 0 on success, 1 for unreadable or unwritable files, 2 for bad options.
)usage";

struct Options {
  std::string shape = "sphere";
  std::vector<double> size;
  std::string mesh, library, out;
  taxel_explore::Settings settings;
  taxel_cli::Format format = taxel_cli::Format::text;
};

std::vector<double> numbers(const taxel_cli::Args& args, std::string_view text) {
  std::vector<double> v;
  std::size_t p = 0;
  while (p <= text.size()) {
    const std::size_t e = std::min(text.find(',', p), text.size());
    double x = 0.0;
    if (!taxel_cli::parse_length(text.substr(p, e - p), x) || !(x > 0.0)) {
      args.fail("--size: '" + std::string(text.substr(p, e - p)) +
                "' is not a positive length (40mm, 0.04)");
    }
    v.push_back(x);
    p = e + 1;
  }
  return v;
}

int run(const Options& o, const taxel_explore::AnyShape& shape, const taxel_cli::Args& args) {
  std::vector<std::pair<std::string, std::string>> meshes;
  std::vector<taxel_explore::TouchRecord> records;
  try {
    records = taxel_explore::explore(shape, o.settings, [&](taxel_explore::TouchRecord& r) {
      if (!o.out.empty()) {
        const auto& e = r.estimate;
        meshes.emplace_back(
            (fs::path(o.out) / ("touch_" + std::to_string(r.touch) + ".ply")).string(),
            taxel::io::encode_ply(e.to_point_cloud(), taxel::io::PlyFormat::binary_little_endian,
                                  e.mesh.triangles));
      }
      r.estimate = {};
    });
  } catch (const std::invalid_argument& e) {
    args.fail(e.what());
  }
  if (!o.out.empty()) {
    try {
      std::error_code ec;
      fs::create_directories(o.out, ec);
      if (ec) throw taxel::IoError(o.out, "cannot create the folder: " + ec.message());
      taxel_cli::write_outputs(meshes);
    } catch (const std::exception& e) {
      args.fail(e.what(), 1);
    }
  }
  const bool recognise = !o.library.empty();
  taxel_cli::Json rows = taxel_cli::Json::array();
  for (const auto& r : records) {
    taxel_cli::Json row = {{"touch", r.touch},
                           {"contacts", r.contacts},
                           {"surface_rms", r.surface_rms},
                           {"surface_signed", r.surface_signed},
                           {"coverage", r.coverage},
                           {"mean_std", r.mean_std}};
    if (recognise) {
      row["top1"] = r.top1.empty() ? taxel_cli::Json(nullptr) : taxel_cli::Json(r.top1);
      row["probability"] = r.probability;
    }
    rows.push_back(std::move(row));
  }
  std::string text;
  if (o.format == taxel_cli::Format::json) {
    text = taxel_cli::render({{"touches", rows}}, o.format);
  } else if (o.format == taxel_cli::Format::csv) {
    text = taxel_cli::render(rows, o.format);
  } else {
    char line[256];
    std::snprintf(line, sizeof line, "%5s %8s %14s %17s %8s %11s%s\n", "touch", "contacts",
                  "surface_rms_mm", "surface_signed_mm", "coverage", "mean_std_mm",
                  recognise ? "  top1 (probability)" : "");
    text = line;
    for (const auto& r : records) {
      std::snprintf(line, sizeof line, "%5d %8zu %14.3f %+17.3f %8.3f %11.3f", r.touch, r.contacts,
                    1e3 * r.surface_rms, 1e3 * r.surface_signed, r.coverage, 1e3 * r.mean_std);
      text += line;
      if (recognise) {
        std::snprintf(line, sizeof line, "  %s (%.3f)", r.top1.empty() ? "-" : r.top1.c_str(),
                      r.probability);
        text += line;
      }
      text += "\n";
    }
  }
  std::fwrite(text.data(), 1, text.size(), stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-explore");
  taxel_cli::print_version_if_asked("taxel-explore", argc, argv);
  taxel_cli::Args args("taxel-explore", argc, argv);
  Options o;
  bool shape_given = false;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--shape") {
      o.shape = std::string(args.choice(taxel_cli::kShapeNames));
      shape_given = true;
    } else if (a == "--size") {
      o.size = numbers(args, args.value());
    } else if (a == "--mesh") {
      o.mesh = std::string(args.value());
    } else if (a == "--policy") {
      const std::string_view p = args.choice("active|random|scripted");
      o.settings.policy = p == "active"   ? taxel_explore::Policy::active
                          : p == "random" ? taxel_explore::Policy::random
                                          : taxel_explore::Policy::scripted;
    } else if (a == "--touches") {
      o.settings.touches = args.number<int>(1, 100000);
    } else if (a == "--candidates") {
      o.settings.candidates = args.number<int>(1, 1000000);
    } else if (a == "--seed") {
      o.settings.seed = args.number<std::uint64_t>(0, std::numeric_limits<std::uint64_t>::max());
    } else if (a == "--library") {
      o.library = std::string(args.value());
    } else if (a == "--grid") {
      o.settings.grid_spacing = args.length(0.2e-3, 0.05);
    } else if (a == "--coverage-radius") {
      o.settings.coverage_radius = args.length(1e-6, 1.0);
    } else if (a == "--out") {
      o.out = std::string(args.value());
    } else if (a == "--format") {
      o.format = taxel_cli::to_format(args.choice("text|json|csv"));
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      args.fail("unexpected argument '" + std::string(a) +
                "': taxel-explore takes no files "
                "but those of --mesh, --library and --out (see --help)");
    }
  }
  if (!o.mesh.empty() && shape_given) args.fail("give --shape or --mesh, not both");
  if (!o.mesh.empty() && !o.size.empty()) args.fail("--size is for --shape, not --mesh");
  if (!o.out.empty() && fs::exists(o.out) && !fs::is_directory(o.out))
    args.fail("--out " + o.out + ": not a folder", 1);

  std::optional<tr::ObjectLibrary<double>> library;
  if (!o.library.empty()) {
    std::error_code ec;
    if (!fs::is_directory(o.library, ec)) args.fail("--library " + o.library + ": not a folder", 1);
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(o.library, ec)) {
      if (e.is_regular_file() && e.path().extension() == ".ply") files.push_back(e.path());
    }
    if (files.empty()) args.fail("--library " + o.library + ": no .ply files in this folder", 1);
    std::sort(files.begin(), files.end());
    library.emplace();
    for (const auto& f : files) {
      try {
        tr::ModelCloud m = tr::model_cloud(taxel::io::read_ply(f.string()));
        library->add(f.stem().string(), std::move(m.cloud));
      } catch (const taxel::IoError& e) {
        args.fail(e.what(), 1);
      } catch (const std::invalid_argument& e) {
        args.fail(f.string() + ": " + e.what(), 1);
      }
    }
    o.settings.library = &*library;
  }

  try {
    if (!o.mesh.empty()) {
      return run(
          o, taxel_explore::AnyShape::of(taxel_cli::read_mesh(o.mesh, 1.0, "taxel-explore", args)),
          args);
    }
    return taxel_cli::with_shape(o.shape, o.size, {}, args, [&](auto shape) {
      return run(o, taxel_explore::AnyShape::of(std::move(shape)), args);
    });
  } catch (const std::invalid_argument& e) {
    args.fail(e.what());
  }
}
