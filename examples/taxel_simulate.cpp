// SPDX-License-Identifier: MIT
// taxel-simulate: simulated tactile explorations of a shape: a contacts CSV (for taxel-fuse)
// and, optionally, the ground-truth surface as PLY.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <taxel/io/contacts_csv.hpp>
#include <taxel/io/npy.hpp>
#include <taxel/io/pad_poses_csv.hpp>
#include <taxel/io/ply.hpp>
#include <taxel/sim.hpp>
#include <vector>

#include "cli.hpp"
#include "report.hpp"
#include "sim_shapes.hpp"

namespace {

namespace ts = taxel::sim;

constexpr const char* kUsage = R"usage(usage: taxel-simulate [options] CONTACTS.csv [TRUTH.ply]

Explores a shape with simulated tactile pads (a Weiss DSA 9205-like 14x6 matrix at 3.4 mm by
default): sliding, grasps of a multi-finger hand, or palpation. Each pad frame turns indentation
into 12-bit readings with depth noise; the pose has kinematic noise. Writes the contacts, with
the anisotropic covariance the noise implies, the normal, pressure and time, as CSV for
taxel-fuse. TRUTH.ply, when given, gets points sampled uniformly over the true surface (at its
pose) with their normals. With --readings and --poses it also writes what a real sensor gives:
the frames' readings as a numpy array (frames, pads, rows, cols) of uint16 and each pad's pose
per frame as the robot believes it (kinematic noise included), the input of taxel-fuse
--readings. Units: metres, seconds, radians.

options:
  --shape sphere|cylinder|box|cone|ellipsoid|torus|mesh   (default sphere)
  --size A[,B[,C]]   sphere: radius (0.04); cylinder: radius, half height (0.03,0.05);
                     box: half extents (0.04,0.03,0.02); cone: radius, height (0.03,0.06);
                     ellipsoid: semi-axes (0.05,0.035,0.025); torus: R, r (0.04,0.015)
  --mesh FILE.ply    the mesh of --shape mesh (closed, outward-oriented triangles)
  --scale F          multiply the mesh's coordinates by F first (--scale 0.001 for a mesh
                     in millimetres)
  --pose X,Y,Z[,RX,RY,RZ]  the object's position and rotation vector (default the origin)
  --exploration sliding|grasp|palpation   (default sliding)
  --contacts N       stop after N contacts, exploring further as needed (default 20000;
                     0: exactly the exploration below)
  --footprint N      where a tactel senses: 1 at its centre (default); 2-4 the mean indentation
                     over its area (N x N points), as a real tactel averages
  --tactel-area      contacts from readings taken as means over the tactels' areas (see
                     taxel-fuse --help; pair with --footprint 2 or more)
  --per-pad          one contact per pad and frame (a quadric fitted to its depth map; one per
                     tactel when under six are active or the quadric does not fit them), not
                     one per tactel
  --slides K         sliding: slides from random starts (default 4)
  --frames F         sliding: frames per slide (default 1000)
  --speed V          sliding speed [m/s] (default 0.05)
  --grasps G         grasp: grasps with random axes (default 8)
  --fingers F        grasp: fingers (default 3), --pads-per-finger P (default 2)
  --touches T        palpation: touches (default 40)
  --pad RxC          tactel rows x columns (default 14x6)
  --pitch P          tactel pitch (default 0.0034)
  --indentation D    how far pads press in, up to 1 m (default 0.001)
  --sigma-normal S   depth noise along the pad normal (default 0.0003)
  --sigma-position S kinematic translation noise (default 0.0002)
  --tilt T           kinematic rotation noise (default 0.02)
  --frame-rate HZ    up to 1e6 (default 1000)
  --seed S           (default 1)
  --truth-points N   samples of the true surface in TRUTH.ply (default 10000)
  --readings F.npy   also write the readings of the frames that gave the contacts
  --poses F.csv      also write the pads' believed poses (frame,pad,x,y,z,qw,qx,qy,qz,time)
  --format text|json|csv   how the summary is printed (default text)
  -h, --help         show this help
  --version          show taxel's version

Lengths take a unit: 3.4mm, 0.34cm, 3400um or 0.0034 (metres); --size and the position of
--pose too (--size 40mm). Any one output may be - for standard output (the summary then goes to
standard error), and --mesh - reads the mesh from standard input.

Exit status: 0 on success, 1 for unreadable or unwritable files, 2 for bad options.
)usage";

struct Options {
  std::string shape = "sphere";
  std::vector<double> size;
  std::string mesh;
  double scale = 1.0;
  std::string exploration = "sliding";
  std::size_t contacts = 20000;
  ts::ExplorationConfig config;
  ts::SlideParams slide;
  ts::GraspParams grasp;
  ts::PalpationParams palpation;
  std::size_t truth_points = 10000;
  std::string readings, poses;
  std::vector<std::string> files;
  taxel_cli::Format format = taxel_cli::Format::text;
  bool to_stdout = false;  // an output is "-": the summary goes to standard error
};

// Comma-separated numbers; lengths (`lengths`: every value, else the first `lengths_first`)
// may carry a unit (4mm).
std::vector<double> numbers(const taxel_cli::Args& args, std::string_view option,
                            std::string_view text, std::size_t lengths_first = 0) {
  std::vector<double> out;
  std::size_t p = 0;
  while (p <= text.size()) {
    const std::size_t e = std::min(text.find(',', p), text.size());
    const std::string_view tok = text.substr(p, e - p);
    double v = 0.0;
    const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    const bool ok = out.size() < lengths_first
                        ? taxel_cli::parse_length(tok, v)
                        : !tok.empty() && res.ec == std::errc() &&
                              res.ptr == tok.data() + tok.size() && std::isfinite(v);
    if (!ok) {
      std::string why(option);
      why.append(": '").append(tok).append(out.size() < lengths_first
                                               ? "' is not a finite length (4mm, 0.004)"
                                               : "' is not a finite number");
      args.fail(why);
    }
    out.push_back(v);
    p = e + 1;
  }
  return out;
}

// The exploration, grown (more frames, grasps or touches) until it holds `want` contacts.
template <class Shape>
ts::Exploration<Shape> explore(const Options& o, const Shape& shape, std::size_t want) {
  const auto once = [&](std::size_t scale) {
    if (o.exploration == "sliding") {
      ts::SlideParams p = o.slide;
      p.frames *= scale;
      return ts::explore_sliding(shape, o.config, p);
    }
    if (o.exploration == "grasp") {
      ts::GraspParams p = o.grasp;
      p.grasps *= static_cast<int>(scale);
      return ts::explore_grasps(shape, o.config, p);
    }
    ts::PalpationParams p = o.palpation;
    p.touches *= static_cast<int>(scale);
    return ts::explore_palpation(shape, o.config, p);
  };
  // A longer exploration until it has enough contacts; on long runs, progress on stderr.
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t scale = 1;; scale *= 2) {
    ts::Exploration<Shape> ex = once(scale);
    if (ex.contact_count() >= want || scale >= 64) return ex;
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (s > 1.0) {
      std::fprintf(stderr,
                   "taxel-simulate: %zu of %zu contacts after %.1f s; exploring %zux longer\n",
                   ex.contact_count(), want, s, 2 * scale);
    }
  }
}

template <class Shape>
int run(const Options& o, const Shape& shape, const taxel_cli::Args& args) {
  const ts::Exploration<Shape> ex = explore(o, shape, o.contacts);
  std::vector<taxel::Contact<double>> contacts = ex.contacts();
  if (o.contacts > 0 && contacts.size() > o.contacts) contacts.resize(o.contacts);
  if (contacts.size() < o.contacts) {
    args.fail("the exploration touched the shape too rarely for " + std::to_string(o.contacts) +
              " contacts (got " + std::to_string(contacts.size()) + ")");
  }
  std::size_t frames = 0;
  for (const auto& f : ex.frames) {
    if (!contacts.empty() && f.time > contacts.back().time) break;
    ++frames;
  }
  // Written as a set: a readings file never lands beside the poses of an earlier run.
  std::vector<std::pair<std::string, std::string>> outputs;
  try {
    outputs.emplace_back(o.files[0], taxel::io::encode_contacts_csv(contacts));
    if (o.files.size() > 1) {
      outputs.emplace_back(o.files[1], taxel::io::encode_ply(ts::sample_surface(
                                           ex.truth, o.truth_points, o.config.seed)));
    }
    if (!o.readings.empty() || !o.poses.empty()) {
      const auto& g = o.config.sensor.geometry;
      const std::size_t pads = frames > 0 ? ex.frames[0].pads.size() : 0;
      std::vector<std::uint16_t> values;
      std::vector<taxel::io::PadPose> poses;
      for (std::size_t f = 0; f < frames; ++f) {
        for (std::size_t p = 0; p < pads; ++p) {
          const auto& pad = ex.frames[f].pads[p];
          values.insert(values.end(), pad.counts.data(), pad.counts.data() + pad.counts.size());
          poses.push_back({f, p, ex.frames[f].time, pad.believed_pose});
        }
      }
      const std::size_t dims[4] = {frames, pads, std::size_t(g.rows), std::size_t(g.cols)};
      if (!o.readings.empty()) {
        outputs.emplace_back(o.readings, taxel::io::encode_npy_u16(dims, values));
      }
      if (!o.poses.empty()) {
        outputs.emplace_back(o.poses, taxel::io::encode_pad_poses_csv(poses));
      }
    }
    taxel_cli::write_outputs(outputs);
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  const taxel_cli::Json summary = {{"shape", o.shape},
                                   {"exploration", o.exploration},
                                   {"contacts", contacts.size()},
                                   {"frames", frames}};
  const std::string text = taxel_cli::render(summary, o.format);
  std::fwrite(text.data(), 1, text.size(), o.to_stdout ? stderr : stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-simulate");
  taxel_cli::print_version_if_asked("taxel-simulate", argc, argv);
  taxel_cli::Args args("taxel-simulate", argc, argv);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Options o;
  taxel::sim::SensorModel& sensor = o.config.sensor;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--shape") {
      o.shape = std::string(args.value());
      if (o.shape != "sphere" && o.shape != "cylinder" && o.shape != "box" && o.shape != "cone" &&
          o.shape != "ellipsoid" && o.shape != "torus" && o.shape != "mesh") {
        args.fail("--shape must be sphere, cylinder, box, cone, ellipsoid, torus or mesh");
      }
    } else if (a == "--size") {
      o.size = numbers(args, "--size", args.value(), std::size_t(-1));
    } else if (a == "--scale") {
      o.scale = args.number<double>(1e-300, 1e300);
    } else if (a == "--mesh") {
      o.mesh = std::string(args.value());
    } else if (a == "--pose") {
      const std::vector<double> v = numbers(args, "--pose", args.value(), 3);
      if (v.size() != 3 && v.size() != 6) args.fail("--pose takes 3 or 6 numbers");
      o.config.object_pose.translation() = taxel::Vec3d(v[0], v[1], v[2]);
      if (v.size() == 6) {
        const taxel::Vec3d r(v[3], v[4], v[5]);
        if (r.norm() > 0)
          o.config.object_pose.linear() = Eigen::AngleAxisd(r.norm(), r.normalized()).matrix();
      }
    } else if (a == "--exploration") {
      o.exploration = std::string(args.value());
      if (o.exploration != "sliding" && o.exploration != "grasp" && o.exploration != "palpation")
        args.fail("--exploration must be sliding, grasp or palpation");
    } else if (a == "--contacts") {
      o.contacts = args.number<std::size_t>(0, std::size_t{1} << 26);
    } else if (a == "--tactel-area") {
      o.config.contacts.tactel_area = true;
    } else if (a == "--per-pad") {
      o.config.contacts.mode = ts::ContactMode::per_pad;
    } else if (a == "--footprint") {
      o.config.footprint = args.number<int>(1, 4);
    } else if (a == "--slides") {
      o.slide.slides = args.number<int>(1, 10000);
    } else if (a == "--frames") {
      o.slide.frames = args.number<std::size_t>(1, std::size_t{1} << 24);
    } else if (a == "--speed") {
      o.slide.speed = args.number<double>(0, 10);
    } else if (a == "--grasps") {
      o.grasp.grasps = args.number<int>(1, 100000);
    } else if (a == "--fingers") {
      o.grasp.fingers = args.number<int>(1, 64);
    } else if (a == "--pads-per-finger") {
      o.grasp.pads_per_finger = args.number<int>(1, 64);
    } else if (a == "--touches") {
      o.palpation.touches = args.number<int>(1, 1000000);
    } else if (a == "--pad") {
      const std::string_view v = args.value();
      const std::size_t x = v.find('x');
      int r = 0, c = 0;
      const auto r1 = std::from_chars(v.data(), v.data() + std::min(x, v.size()), r);
      const auto r2 = x == std::string_view::npos
                          ? std::from_chars_result{v.data(), std::errc::invalid_argument}
                          : std::from_chars(v.data() + x + 1, v.data() + v.size(), c);
      if (r1.ec != std::errc() || r2.ec != std::errc() || r1.ptr != v.data() + x ||
          r2.ptr != v.data() + v.size() || r < 1 || c < 1 || r > 256 || c > 256) {
        args.fail("--pad takes ROWSxCOLS, each in [1, 256], e.g. 14x6");
      }
      sensor.geometry.rows = r;
      sensor.geometry.cols = c;
    } else if (a == "--pitch") {
      sensor.geometry.pitch = args.length(-kInf, kInf);
    } else if (a == "--indentation") {
      o.config.indentation = args.length(-kInf, kInf);
    } else if (a == "--sigma-normal") {
      sensor.sigma_normal = args.length(-kInf, kInf);
    } else if (a == "--sigma-position") {
      sensor.sigma_position = args.length(-kInf, kInf);
    } else if (a == "--tilt") {
      sensor.sigma_tilt = args.number<double>(-kInf, kInf);
    } else if (a == "--frame-rate") {
      o.config.frame_rate = args.number<double>(-kInf, kInf);
    } else if (a == "--seed") {
      o.config.seed = args.number<std::uint64_t>(0, std::numeric_limits<std::uint64_t>::max());
    } else if (a == "--readings") {
      o.readings = std::string(args.value());
    } else if (a == "--poses") {
      o.poses = std::string(args.value());
    } else if (a == "--truth-points") {
      o.truth_points = args.number<std::size_t>(1, std::size_t{1} << 26);
    } else if (a == "--format") {
      o.format = taxel_cli::to_format(args.choice("text|json|csv"));
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.files.emplace_back(a);
    }
  }
  if (o.files.empty() || o.files.size() > 2)
    args.fail("expected CONTACTS.csv [TRUTH.ply] (see --help)");
  {
    int dash = 0;
    for (const std::string* f : {&o.readings, &o.poses}) dash += *f == "-";
    for (const std::string& f : o.files) dash += f == "-";
    if (dash > 1) args.fail("only one output can be standard output (-)");
    o.to_stdout = dash == 1;
  }
  if (o.shape == "mesh" && o.mesh.empty()) args.fail("--shape mesh needs --mesh FILE.ply");
  if (o.shape != "mesh" && !o.mesh.empty()) args.fail("--mesh is only used with --shape mesh");
  if (o.shape != "mesh" && o.scale != 1.0) args.fail("--scale is only used with --shape mesh");
  {
    const std::string truth = o.files.size() > 1 ? o.files[1] : std::string();
    args.check_output(o.files[0], {o.mesh}, {truth, o.readings, o.poses});
    args.check_output(truth, {o.mesh}, {o.readings, o.poses});
    args.check_output(o.readings, {o.mesh}, {o.poses});
    args.check_output(o.poses, {o.mesh});
  }
  try {
    o.config.validate();
    if (o.shape == "mesh")
      return run(o, taxel_cli::read_mesh(o.mesh, o.scale, "taxel-simulate", args), args);
    taxel_cli::ShapeSizes sizes;
    sizes.sphere = {0.04};
    sizes.cylinder = {0.03, 0.05};
    sizes.ellipsoid = {0.05, 0.035, 0.025};
    sizes.torus = {0.04, 0.015};
    return taxel_cli::with_shape(o.shape, o.size, sizes, args,
                                 [&](const auto& shape) { return run(o, shape, args); });
  } catch (const std::invalid_argument& e) {  // a shape or exploration parameter out of range
    args.fail(e.what());
  }
}
