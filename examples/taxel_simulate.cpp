// SPDX-License-Identifier: MIT
// taxel-simulate: simulated tactile explorations of a shape: a contacts CSV (for taxel-fuse)
// and, optionally, the ground-truth surface as PLY.
#include <algorithm>
#include <charconv>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <taxel/io/contacts_csv.hpp>
#include <taxel/io/ply.hpp>
#include <taxel/sim.hpp>
#include <vector>

#include "cli.hpp"

namespace {

namespace ts = taxel::sim;

constexpr const char* kUsage = R"usage(usage: taxel-simulate [options] CONTACTS.csv [TRUTH.ply]

Slides a simulated tactile pad over a shape (several slides from random starts, a random-walk
heading) and writes the contacts, with their anisotropic pad covariance, normal and time, as
CSV for taxel-fuse. TRUTH.ply, when given, gets points sampled uniformly over the true surface
with their normals. Units: metres, seconds, radians.

options:
  --shape sphere|cylinder|box|cone|mesh   (default sphere)
  --size A[,B[,C]]   sphere: radius (0.04); cylinder: radius, half height (0.03,0.05);
                     box: half extents (0.04,0.03,0.02); cone: radius, height (0.03,0.06)
  --mesh FILE.ply    the mesh of --shape mesh (closed, outward-oriented triangles)
  --contacts N       contacts to write (default 20000)
  --slides K         slides from random starts (default 4)
  --pitch P          tactel pitch (default 0.0034)
  --sigma-normal S   contact noise along the pad normal (default 0.001)
  --tilt T           kinematic tilt noise per frame (default 0.05)
  --speed V          sliding speed [m/s] (default 0.05)
  --seed S           (default 1)
  --truth-points N   samples of the true surface in TRUTH.ply (default 10000)
  -h, --help         show this help

Exit status: 0 on success, 1 for unreadable or unwritable files, 2 for bad options.
)usage";

struct Options {
  std::string shape = "sphere";
  std::vector<double> size;
  std::string mesh;
  std::size_t contacts = 20000;
  int slides = 4;
  ts::SlidingConfig sliding;
  std::size_t truth_points = 10000;
  std::vector<std::string> files;
};

std::vector<double> numbers(const taxel_cli::Args& args, std::string_view text) {
  std::vector<double> out;
  std::size_t p = 0;
  while (p <= text.size()) {
    const std::size_t e = std::min(text.find(',', p), text.size());
    const std::string_view tok = text.substr(p, e - p);
    double v = 0.0;
    const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (tok.empty() || res.ec != std::errc() || res.ptr != tok.data() + tok.size()) {
      args.fail("--size: '" + std::string(tok) + "' is not a number");
    }
    out.push_back(v);
    p = e + 1;
  }
  return out;
}

template <class Shape>
int run(const Options& o, const Shape& shape, const taxel_cli::Args& args) {
  std::vector<taxel::Contact<double>> contacts;
  contacts.reserve(o.contacts);
  for (int s = 0; s < o.slides; ++s) {
    ts::SlidingConfig c = o.sliding;
    c.seed = o.sliding.seed * 7919 + static_cast<std::uint64_t>(s);
    const std::size_t left = o.contacts - contacts.size();
    const std::size_t n =
        s + 1 == o.slides ? left : std::min(left, o.contacts / static_cast<std::size_t>(o.slides));
    const auto part = ts::sliding_exploration(shape, n, c);
    contacts.insert(contacts.end(), part.begin(), part.end());
  }
  try {
    taxel::io::write_contacts_csv(o.files[0], contacts);
    if (o.files.size() > 1) {
      taxel::io::write_ply(o.files[1], ts::sample_surface(shape, o.truth_points, o.sliding.seed));
    }
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  std::printf("shape %s\ncontacts %zu\nslides %d\n", o.shape.c_str(), contacts.size(), o.slides);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::Args args("taxel-simulate", argc, argv);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--shape") {
      o.shape = std::string(args.value());
      if (o.shape != "sphere" && o.shape != "cylinder" && o.shape != "box" && o.shape != "cone" &&
          o.shape != "mesh") {
        args.fail("--shape must be sphere, cylinder, box, cone or mesh");
      }
    } else if (a == "--size") {
      o.size = numbers(args, args.value());
    } else if (a == "--mesh") {
      o.mesh = std::string(args.value());
    } else if (a == "--contacts") {
      o.contacts = args.number<std::size_t>(1, std::size_t{1} << 26);
    } else if (a == "--slides") {
      o.slides = args.number<int>(1, 10000);
    } else if (a == "--pitch") {
      o.sliding.pitch = args.number<double>(-kInf, kInf);
    } else if (a == "--sigma-normal") {
      o.sliding.sigma_normal = args.number<double>(-kInf, kInf);
    } else if (a == "--tilt") {
      o.sliding.sigma_tilt = args.number<double>(-kInf, kInf);
    } else if (a == "--speed") {
      o.sliding.speed = args.number<double>(-kInf, kInf);
    } else if (a == "--seed") {
      o.sliding.seed = args.number<std::uint64_t>(0, std::numeric_limits<std::uint64_t>::max());
    } else if (a == "--truth-points") {
      o.truth_points = args.number<std::size_t>(1, std::size_t{1} << 26);
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.files.emplace_back(a);
    }
  }
  if (o.files.empty() || o.files.size() > 2)
    args.fail("expected CONTACTS.csv [TRUTH.ply] (see --help)");
  if (o.shape == "mesh" && o.mesh.empty()) args.fail("--shape mesh needs --mesh FILE.ply");
  if (o.shape != "mesh" && !o.mesh.empty()) args.fail("--mesh is only used with --shape mesh");
  const auto dims = [&](std::size_t n, std::vector<double> fallback) {
    if (o.size.empty()) return fallback;
    if (o.size.size() != n) {
      args.fail("--size for a " + o.shape + " takes " + std::to_string(n) + " number(s), got " +
                std::to_string(o.size.size()));
    }
    return o.size;
  };
  try {
    if (o.shape == "sphere") return run(o, ts::Sphere(dims(1, {0.04})[0]), args);
    if (o.shape == "cylinder") {
      const auto d = dims(2, {0.03, 0.05});
      return run(o, ts::Cylinder(d[0], d[1]), args);
    }
    if (o.shape == "box") {
      const auto d = dims(3, {0.04, 0.03, 0.02});
      return run(o, ts::Box(taxel::Vec3d(d[0], d[1], d[2])), args);
    }
    if (o.shape == "cone") {
      const auto d = dims(2, {0.03, 0.06});
      return run(o, ts::Cone(d[0], d[1]), args);
    }
    taxel::io::PlyData ply;
    try {
      ply = taxel::io::read_ply(o.mesh);
    } catch (const std::exception& e) {
      args.fail(e.what(), 1);
    }
    return run(o, ts::TriangleMesh(ply.cloud.points, ply.triangles), args);
  } catch (const std::invalid_argument& e) {  // a shape or exploration parameter out of range
    args.fail(e.what());
  }
}
