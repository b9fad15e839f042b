// SPDX-License-Identifier: MIT
// taxel-recognize: ranks object models (PLY files, or every .ply in a folder) by how well a
// tactile cloud (PLY) aligns to each, by multi-start ICP (registration::ObjectLibrary).
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <taxel/io/ply.hpp>
#include <taxel/registration.hpp>
#include <vector>

namespace {

namespace tr = taxel::registration;
namespace fs = std::filesystem;

constexpr const char* kUsage = R"usage(usage: taxel-recognize [options] CLOUD.ply MODEL...

Recognises the object a tactile cloud was taken from: every MODEL (a .ply file, or a folder
whose .ply files are all models; the name is the file name without .ply) is aligned to the
cloud from 28 starts (4 principal-axes, 24 cube rotations) and scored by the truncated RMS
distance of the cloud's points to it. Prints the ranking, best first, then the answer: the best
model's name, or "unknown" when even it scores above --unknown. Distances in metres.

options:
  --unknown D        answer unknown above this score (default 0.003)
  --gate D           points farther than D count as D in the score (default 0.01)
  --starts N         cube-rotation starts, 0..24 (default 24)
  --format text|json (default text)
  -h, --help         show this help

Exit status: 0 when the cloud was ranked, 1 for unreadable input, 2 for bad options.
)usage";

[[noreturn]] void die(const std::string& why, int code = 2) {
  std::fprintf(stderr, "taxel-recognize: %s\n", why.c_str());
  std::exit(code);
}

double number(std::string_view flag, std::string_view text) {
  double v = 0.0;
  const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
  if (res.ec != std::errc() || res.ptr != text.data() + text.size()) {
    die(std::string(flag) + ": '" + std::string(text) + "' is not a number");
  }
  return v;
}

std::string json_escape(std::string_view s) {
  std::string out;
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(static_cast<unsigned char>(c) < 0x20 ? ' ' : c);
  }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  tr::LibraryConfig cfg;
  bool json = false;
  std::vector<std::string> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    auto value = [&]() -> std::string_view {
      if (i + 1 >= argc) die(std::string(a) + " needs a value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--unknown") {
      cfg.unknown_score = number(a, value());
    } else if (a == "--gate") {
      cfg.score_gate = number(a, value());
    } else if (a == "--starts") {
      const double n = number(a, value());
      if (n != static_cast<int>(n)) die("--starts must be an integer");
      cfg.rotation_starts = static_cast<int>(n);
    } else if (a == "--format") {
      const auto v = value();
      if (v != "text" && v != "json") die("--format must be text or json");
      json = v == "json";
    } else if (a.size() > 1 && a[0] == '-') {
      die("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      inputs.emplace_back(a);
    }
  }
  if (inputs.size() < 2) die("expected CLOUD.ply and at least one MODEL (see --help)");

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
  try {
    tr::ObjectLibrary<double> lib(cfg);
    for (const auto& m : models) lib.add(m.stem().string(), taxel::io::read_ply(m.string()).cloud);
    r = lib.recognize(taxel::io::read_ply(inputs[0]).cloud);
  } catch (const taxel::IoError& e) {
    die(e.what(), 1);
  } catch (const std::invalid_argument& e) {
    die(e.what(), 2);
  }
  if (!r.ok()) die(inputs[0] + ": " + r.message, 1);

  if (json) {
    std::printf("{\"best\": \"%s\", \"unknown\": %s, \"margin\": %.9g, \"ranking\": [",
                json_escape(r.best).c_str(), r.unknown ? "true" : "false", r.margin);
    for (std::size_t k = 0; k < r.ranking.size(); ++k) {
      const auto& m = r.ranking[k];
      std::printf("%s\n  {\"model\": \"%s\", \"score\": %.9g, \"rmse\": %.9g, \"fitness\": %.6f}",
                  k ? "," : "", json_escape(m.name).c_str(), m.score, m.rmse, m.inlier_fraction);
    }
    std::printf("\n]}\n");
    return 0;
  }
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
  return 0;
}
