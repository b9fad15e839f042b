// SPDX-License-Identifier: MIT
// taxel-fuse: a contact stream (CSV) in, the fused cloud (PLY) out, with the fusion policy and
// the spatial index chosen by option.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <string_view>
#include <taxel/fusion.hpp>
#include <taxel/index.hpp>
#include <taxel/io/contacts_csv.hpp>
#include <taxel/io/ply.hpp>
#include <taxel/sensor/readings.hpp>
// The drivers' headers used here (session replay, frames to contacts) need no libusb.
#include <taxel/drivers/convert.hpp>
#include <taxel/drivers/session.hpp>
#include <vector>

#include "cli.hpp"
#include "report.hpp"

namespace {

constexpr const char* kUsage = R"usage(usage: taxel-fuse [options] CONTACTS.csv CLOUD.ply
       taxel-fuse [options] --readings STACK.npy --poses POSES.csv CLOUD.ply
       taxel-fuse [options] --session SESSION.txt [--poses POSES.csv] CLOUD.ply

Fuses a contact stream into a compact cloud: each contact joins the nearest fused point within
the association radius (wider for a contact whose noise along its normal is coarse: see
--association-sigmas), or starts a new one. The contacts come from a CSV, or from pad
readings and the pads' poses, turned into contacts by taxel's sensor model (a local surface
normal from each pad's depth map, the noise floor's censoring removed, the covariance tight
along that normal; include/taxel/sensor/contacts.hpp).

STACK.npy is a numpy array of integer readings of shape (frames, rows, cols) for one pad or
(frames, pads, rows, cols); POSES.csv has the header frame,pad,x,y,z,qw,qx,qy,qz[,time]: per
frame and pad, the pad origin [m] and the pad -> world rotation as a unit quaternion (the pad
frame: tactel rows along y, columns along x, the sensing face along +z, into the object). A pad
that reads contact must have a pose. SESSION.txt is a DSACON32m session recorded by
taxel-record; its matrices' geometry comes from the controller, their poses from POSES.csv (as
taxel-record --poses writes it, columns time_ms,matrix,...) or else the controller's static
matrix poses.

CONTACTS.csv has a header naming its columns
(time, x, y, z, cxx, cxy, cxz, cyy, cyz, czz, nx, ny, nz, pressure, normal_sigma,
footprint_sigma; x, y, z required; see include/taxel/io/contacts_csv.hpp). The covariance
across the normal is scatter of the position (surfel removes the lift it gives on a curved
surface) except for footprint_sigma^2, a tactel's footprint around a point on the surface
(contacts from readings state pitch / sqrt(12)). CLOUD.ply gets the fused points with their
normals (surfel) and the properties "observations", the covariance "cov_xx", "cov_xy",
"cov_xz", "cov_yy", "cov_yz", "cov_zz" [m^2] and "last_time". Units: metres and seconds.

options:
  --policy surfel|kalman|average|raw    fusion policy (default surfel: a Kalman point that
                    fits its patch's curvature from the contact normals and removes the
                    chord sag; kalman: the plain per-point Kalman filter; average: running
                    mean; raw: every contact kept)
  --index voxel-hash|kd-tree|brute-force   spatial index (default voxel-hash)
  --radius R        association radius [m] (default 0.0034, one DSA tactel pitch)
  --association-sigmas K   widen the gate to K standard deviations of a contact's noise
                    along its normal when that is larger than R, so that a coarse contact's
                    noise tail cannot start a point off the surface (default 6; 0: off)
  --gate CHI2       surfel, kalman: Mahalanobis gate (e.g. 11.345 for 99 %; default none)
  --process-noise Q surfel, kalman: process noise [m] per update (default 0)
  --min-observations N   keep only points with at least N contacts (default 1: all)
  --max-sigma S     keep only points whose largest standard deviation is at most S [m]
  --max-normal-sigma S  keep only points whose smallest standard deviation (across the
                    surface) is at most S [m]: 0.3mm drops points only a coarse pad has seen
  --ascii           write ASCII PLY (default binary little-endian)
  --strict          refuse a CONTACTS.csv with any bad row or unknown column (default: skip
                    bad rows, counted as "skipped_rows" with the first one's reason on
                    standard error, and ignore unknown columns, named once)
  --scale F         multiply the contacts' positions by F (covariances by F^2): --scale 0.001
                    for a CSV in millimetres (CONTACTS.csv only)
readings (--readings, --session):
  --per-pad         one contact per pad and frame (default: one per active tactel; a frame
                    with under six active tactels, or whose depths the frame's quadric does
                    not fit, gives one per tactel)
  --tactel-area     a reading is the mean indentation over the tactel's area (a real
                    tactel), not at its centre: move each depth to the centre's where the
                    frame's quadric fits (default: readings at the centres)
  --pitch P         tactel pitch [m] (default 0.0034; --readings only)
  --levels L        reading levels, e.g. 4096 for 12 bits (default 4096; --readings only)
  --full-scale-depth D   indentation at the largest reading [m] (default 0.003)
  --threshold T     readings below T are no contact (default 8)
  --sigma-normal S  depth noise of a reading [m] (default 0.0003)
  --sigma-position S  pad position noise from the kinematics [m] (default 0.0002)
  --sigma-tilt S    pad rotation noise from the kinematics [rad] (default 0.02)
  --frame-rate F    frames per second, for poses without a time (default 1000)

  --format text|json|csv   how the summary is printed (default text)
  -h, --help        show this help
  --version         show taxel's version

Lengths take a unit: 3.4mm, 0.34cm, 3400um or 0.0034 (metres). CONTACTS.csv may be - for
standard input and CLOUD.ply - for standard output; the summary then goes to standard error.

Prints a summary: the counts (contacts, added, fused, rejected and rejected_by reason, rows of
CONTACTS.csv skipped, points, points written), the time per contact and, for readings and
sessions, what was read.
Exit status: 0 on success, 1 for unreadable input or a lost write, 2 for bad options.
)usage";

struct Options {
  std::string policy = "surfel";
  std::string index = "voxel-hash";
  double radius = 3.4e-3;
  double association_sigmas = 6.0;
  double gate = 0.0;
  double process_noise = 0.0;
  bool ascii = false;
  bool strict = false;
  std::uint32_t min_observations = 1;
  std::string readings, poses, session;
  bool per_pad = false;
  bool tactel_area = false;
  double frame_rate = 1000.0;
  taxel::sensor::SensorModel model;
  double max_sigma = std::numeric_limits<double>::infinity();
  double max_normal_sigma = std::numeric_limits<double>::infinity();
  double scale = 1.0;
  taxel_cli::Format format = taxel_cli::Format::text;
  std::vector<std::string> files;
};

// Rows of CONTACTS.csv skipped as bad (not --strict), for the summary.
std::size_t skipped_rows = 0;

// The summary, printed at the end (to standard error when the cloud goes to standard output).
taxel_cli::Json summary = taxel_cli::Json::object();

// "covariance is not finite" -> "covariance_is_not_finite": a field name in every format.
std::string field_name(std::string_view why) {
  std::string s(why);
  for (char& c : s) c = c == ' ' ? '_' : c;
  return s;
}

void print_summary(const Options& o) {
  const std::string text = taxel_cli::render(summary, o.format);
  std::fwrite(text.data(), 1, text.size(), o.files[1] == "-" ? stderr : stdout);
}

// Where the contacts come from: fills `batch` (cleared first) with the next contacts and returns
// false once the input is used up. A CSV is read a batch at a time, so that a stream of any
// length is fused in memory that depends on the cloud, not on the file.
using Feed = std::function<bool(std::vector<taxel::Contact<double>>&)>;

template <class Cloud>
int fuse(const Options& o, typename Cloud::Config cfg, const Feed& feed,
         const taxel_cli::Args& args) {
  cfg.association_radius = o.radius;
  cfg.association_sigmas = o.association_sigmas;
  Cloud cloud(cfg);
  std::map<std::string, std::size_t> rejected;
  std::size_t contacts = 0, added = 0, fused = 0;
  double s = 0.0;  // seconds spent inserting
  std::vector<taxel::Contact<double>> batch;
  for (bool more = true; more;) {
    try {
      more = feed(batch);
    } catch (const std::exception& e) {
      args.fail(e.what(), 1);
    }
    contacts += batch.size();
    const auto t0 = std::chrono::steady_clock::now();
    for (const auto& c : batch) {
      const auto r = cloud.insert(c);
      switch (r.status) {
        case taxel::fusion::InsertStatus::added:
          ++added;
          break;
        case taxel::fusion::InsertStatus::fused:
          ++fused;
          break;
        default:
          ++rejected[std::string(taxel::to_string(r.defect))];
      }
    }
    s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  }
  summary["contacts"] = contacts;
  summary["added"] = added;
  summary["fused"] = fused;
  std::size_t total_rejected = 0;
  auto by = taxel_cli::Json::object();
  for (const auto& [why, n] : rejected) {
    total_rejected += n;
    by[field_name(why)] = n;
  }
  summary["rejected"] = total_rejected;
  if (!by.empty()) summary["rejected_by"] = by;
  summary["skipped_rows"] = skipped_rows;
  summary["points"] = cloud.size();
  summary["ns_per_contact"] =
      std::llround(contacts == 0 ? 0.0 : 1e9 * s / static_cast<double>(contacts));
  if (contacts > 0 && total_rejected == contacts) {
    // Nothing to write is a failed run, not an empty success (a --scale or --radius far off
    // makes every contact out of range).
    const bool range =
        rejected.count(std::string(taxel::to_string(taxel::ContactDefect::out_of_range))) > 0;
    args.fail(
        "every one of the " + std::to_string(contacts) + " contacts was rejected (" +
            rejected.begin()->first + (rejected.size() > 1 ? ", ..." : "") + ")" +
            (range ? "; the index's range shrinks with --radius: check --radius and --scale" : "") +
            "; no cloud written",
        1);
  }
  if (o.policy != "raw" && fused == 0 && added >= 100) {  // raw never fuses
    std::fprintf(stderr,
                 "taxel-fuse: warning: no contact fused with another: the association radius "
                 "(%g m) is below the contacts' spacing; are they in millimetres (--scale "
                 "0.001)?\n",
                 o.radius);
  }
  const auto kept = cloud.to_point_cloud({o.min_observations, o.max_sigma, o.max_normal_sigma});
  summary["written"] = kept.size();
  try {
    taxel_cli::write_output(
        o.files[1],
        taxel::io::encode_ply(kept, o.ascii ? taxel::io::PlyFormat::ascii
                                            : taxel::io::PlyFormat::binary_little_endian));
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  print_summary(o);
  return 0;
}

template <class Policy>
int with_index(const Options& o, typename Policy::Config pc, const Feed& feed,
               const taxel_cli::Args& args) {
  namespace tf = taxel::fusion;
  namespace ti = taxel::index;
  if (o.index == "kd-tree") {
    typename tf::ContactCloud<Policy, ti::DynamicKdTree<double>>::Config cfg;
    cfg.fusion = pc;
    return fuse<tf::ContactCloud<Policy, ti::DynamicKdTree<double>>>(o, cfg, feed, args);
  }
  if (o.index == "brute-force") {
    typename tf::ContactCloud<Policy, ti::BruteForce<double>>::Config cfg;
    cfg.fusion = pc;
    return fuse<tf::ContactCloud<Policy, ti::BruteForce<double>>>(o, cfg, feed, args);
  }
  typename tf::ContactCloud<Policy, ti::VoxelHash<double>>::Config cfg;
  cfg.fusion = pc;
  return fuse<tf::ContactCloud<Policy, ti::VoxelHash<double>>>(o, cfg, feed, args);
}

// The contacts of a recorded DSACON32m session: each frame's matrices at the poses of the frame's
// time stamp in POSES.csv (as taxel-record --poses writes them), else at the controller's static
// matrix poses. Throws on a malformed file, a pose file that does not fit the session, or a
// replay that fails. Returns why the replay fell short of the whole recording ("" when it did
// not).
std::string session_contacts(const Options& o, const taxel::sensor::ContactOptions& copt,
                             std::vector<taxel::Contact<double>>& out) {
  namespace td = taxel::drivers;
  td::SessionPrefix file = td::read_session_prefix(o.session);
  if (file.chunks.empty() && !file.error.empty()) throw td::SessionError(file.error);
  // A replay answers at once or never: waiting on it only delays the message.
  td::DsaconDevice dev(td::ReplayTransport(std::move(file.chunks)),
                       {.reply_timeout = td::Timeout(50), .frame_timeout = td::Timeout(50)});
  try {
    dev.open();
    dev.start();
  } catch (const std::exception& e) {  // the damage lies in the handshake itself
    const std::uint64_t line = dev.transport().last_read_line();
    throw std::runtime_error(
        o.session + ": the recorded handshake fails: " + e.what() +
        (line > 0 ? " (the device's bytes read last are on line " + std::to_string(line) + ")"
                  : std::string()) +
        (file.error.empty() ? std::string() : "; " + file.error));
  }
  const std::vector<Eigen::Isometry3d> fixed = td::static_matrix_poses(dev.matrices());
  td::SessionPoses table;
  if (!o.poses.empty()) {
    table = td::SessionPoses(taxel_cli::read_input(o.poses), taxel_cli::input_name(o.poses),
                             dev.matrices().size());
  }
  td::PadCalibration cal;
  cal.full_scale_depth = o.model.full_scale_depth;
  cal.threshold = o.model.threshold;
  cal.sigma_normal = o.model.sigma_normal;
  cal.sigma_position = o.model.sigma_position;
  cal.sigma_tilt = o.model.sigma_tilt;
  std::size_t frames = 0, posed = 0;
  std::vector<Eigen::Isometry3d> poses;
  while (const auto f = dev.read_frame()) {
    ++frames;
    if (table.frame_poses(*f, fixed, cal.threshold, taxel_cli::input_name(o.poses), poses)) {
      ++posed;
    }
    td::frame_contacts(*f, dev.matrices(), poses, out, copt.mode, cal, copt);
  }
  const std::size_t matrices = dev.matrices().size();
  const std::string shortfall = td::finish_replay(dev, file.error);
  summary["session"] = {{"frames", frames}, {"frames_with_poses", posed}, {"matrices", matrices}};
  return shortfall;
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-fuse");
  taxel_cli::print_version_if_asked("taxel-fuse", argc, argv);
  taxel_cli::Args args("taxel-fuse", argc, argv);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kTiny = std::numeric_limits<double>::min();  // the least positive value
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--policy") {
      o.policy = std::string(args.value());
      if (o.policy != "surfel" && o.policy != "kalman" && o.policy != "average" &&
          o.policy != "raw") {
        args.fail("--policy must be surfel, kalman, average or raw");
      }
    } else if (a == "--index") {
      o.index = std::string(args.value());
      if (o.index != "voxel-hash" && o.index != "kd-tree" && o.index != "brute-force") {
        args.fail("--index must be voxel-hash, kd-tree or brute-force");
      }
    } else if (a == "--radius") {
      o.radius = args.length(-kInf, kInf);
    } else if (a == "--association-sigmas") {
      o.association_sigmas = args.number<double>(-kInf, kInf);
    } else if (a == "--gate") {
      o.gate = args.number<double>(-kInf, kInf);
    } else if (a == "--process-noise") {
      o.process_noise = args.length(-kInf, kInf);
    } else if (a == "--min-observations") {
      o.min_observations = args.number<std::uint32_t>(1, 4294967295u);
    } else if (a == "--max-sigma") {
      o.max_sigma = args.length(0.0, kInf);
    } else if (a == "--max-normal-sigma") {
      o.max_normal_sigma = args.length(0.0, kInf);
    } else if (a == "--strict") {
      o.strict = true;
    } else if (a == "--ascii") {
      o.ascii = true;
    } else if (a == "--scale") {
      o.scale = args.number<double>(1e-300, 1e300);
    } else if (a == "--readings") {
      o.readings = std::string(args.value());
    } else if (a == "--poses") {
      o.poses = std::string(args.value());
    } else if (a == "--session") {
      o.session = std::string(args.value());
    } else if (a == "--per-pad") {
      o.per_pad = true;
    } else if (a == "--tactel-area") {
      o.tactel_area = true;
    } else if (a == "--pitch") {
      o.model.geometry.pitch = args.length(1e-6, 1.0);  // SensorModel's ranges, checked here
                                                        // before any input is read
    } else if (a == "--levels") {
      o.model.levels = args.number<int>(2, 65536);
    } else if (a == "--full-scale-depth") {
      o.model.full_scale_depth = args.length(kTiny, 1.0);
    } else if (a == "--threshold") {
      o.model.threshold = args.number<int>(1, 65535);
    } else if (a == "--sigma-normal") {
      o.model.sigma_normal = args.length(0.0, 1.0);
    } else if (a == "--sigma-position") {
      o.model.sigma_position = args.length(0.0, 1.0);
    } else if (a == "--sigma-tilt") {
      o.model.sigma_tilt = args.number<double>(0.0, std::numbers::pi);
    } else if (a == "--frame-rate") {
      o.frame_rate = args.number<double>(kTiny, std::numeric_limits<double>::max());
    } else if (a == "--format") {
      o.format = taxel_cli::to_format(args.choice("text|json|csv"));
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.files.emplace_back(a);
    }
  }
  if (o.model.threshold >= o.model.levels) {
    args.fail("--threshold " + std::to_string(o.model.threshold) + " must be below --levels " +
              std::to_string(o.model.levels));
  }
  const bool from_readings = !o.readings.empty(), from_session = !o.session.empty();
  if (from_readings && from_session) args.fail("--readings and --session exclude each other");
  if (from_readings && o.poses.empty()) args.fail("--readings needs --poses POSES.csv");
  if ((from_readings || from_session) && o.scale != 1.0) {
    args.fail(
        "--scale applies to CONTACTS.csv; the readings' geometry is set in metres by "
        "--pitch and --full-scale-depth");
  }
  if (!from_readings && !from_session && !o.poses.empty()) {
    args.fail("--poses goes with --readings or --session");
  }
  const std::size_t want = from_readings || from_session ? 1 : 2;
  if (o.files.size() != want) {
    args.fail(want == 1 ? "expected CLOUD.ply after the readings options (see --help)"
                        : "expected CONTACTS.csv and CLOUD.ply (see --help)");
  }
  if (want == 1) o.files.insert(o.files.begin(), std::string());
  if ((o.files[0] == "-") + (o.readings == "-") + (o.poses == "-") > 1) {
    args.fail("only one input can be standard input (-)");
  }
  args.check_output(o.files[1], {o.files[0], o.readings, o.poses, o.session});
  taxel::sensor::ContactOptions copt;
  copt.mode =
      o.per_pad ? taxel::sensor::ContactMode::per_pad : taxel::sensor::ContactMode::per_tactel;
  copt.tactel_area = o.tactel_area;
  std::string shortfall;  // a session replay that ended early: the output is kept, exit 1
  // Readings and sessions become contacts in memory (a stack of readings is itself held
  // whole); a CSV is read a batch at a time.
  const auto whole = [&](std::vector<taxel::Contact<double>>& batch) {
    batch.clear();
    if (from_readings) {
      auto stack = taxel::sensor::ReadingStack::from_npy(taxel::io::parse_npy_u16(
          taxel_cli::read_input(o.readings), taxel_cli::input_name(o.readings)));
      const auto poses = taxel::io::parse_pad_poses_csv(taxel_cli::read_input(o.poses),
                                                        taxel_cli::input_name(o.poses));
      taxel::sensor::SensorModel model = o.model;
      model.geometry.rows = static_cast<int>(stack.rows);
      model.geometry.cols = static_cast<int>(stack.cols);
      const auto r =
          taxel::sensor::contacts_from_readings(stack, poses, model, copt, o.frame_rate, batch);
      summary["readings"] = {{"frames", stack.frames},     {"pads", stack.pads},
                             {"rows", stack.rows},         {"cols", stack.cols},
                             {"pad_frames", r.pad_frames}, {"touching", r.touching}};
    } else {
      shortfall = session_contacts(o, copt, batch);
      if (!shortfall.empty()) {
        std::fprintf(stderr, "taxel-fuse: %s: %s; fusing the frames before it (exit 1)\n",
                     o.session.c_str(), shortfall.c_str());
      }
    }
    return false;
  };
  const std::string name = taxel_cli::input_name(o.files[0]);
  std::optional<taxel::io::ContactsCsvReader> csv;
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  const auto stream = [&](std::vector<taxel::Contact<double>>& batch) {
    batch.clear();
    if (!csv) {
      csv.emplace(o.files[0] == "-" ? std::string("/dev/stdin") : o.files[0],
                  taxel::io::ContactsCsvOptions{.strict = o.strict}, name);
    }
    const bool more = csv->read(batch, std::size_t{1} << 16);
    for (auto& c : batch) {
      c.position *= o.scale;
      c.covariance *= o.scale * o.scale;
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], c.position[k]);
        hi[k] = std::max(hi[k], c.position[k]);
      }
    }
    if (!more) {  // the whole file is read: what was left out, and the units
      const auto& report = csv->report();
      const std::size_t shown = std::min<std::size_t>(report.ignored_columns.size(), 5);
      for (std::size_t k = 0; k < shown; ++k) {
        std::fprintf(stderr, "taxel-fuse: %s: ignoring unknown column '%s'\n", name.c_str(),
                     taxel::printable(report.ignored_columns[k]).c_str());
      }
      if (report.ignored_columns.size() > shown) {
        std::fprintf(stderr, "taxel-fuse: %s: ignoring %zu more unknown columns\n", name.c_str(),
                     report.ignored_columns.size() - shown);
      }
      skipped_rows = report.skipped_rows;
      if (report.skipped_rows > 0) {
        std::fprintf(stderr,
                     "taxel-fuse: skipped %zu bad rows (--strict refuses them); the first: %s\n",
                     report.skipped_rows, report.first_skipped.c_str());
      }
      double extent = 0.0;
      for (int k = 0; k < 3; ++k) extent = std::max(extent, hi[k] - lo[k]);
      taxel_cli::warn_if_millimetres("taxel-fuse", name, extent);
    }
    return more;
  };
  const Feed feed = from_readings || from_session ? Feed(whole) : Feed(stream);
  namespace tf = taxel::fusion;
  try {
    int code = 0;
    tf::Kalman<double>::Config kc;
    kc.process_noise = o.process_noise;
    if (o.gate != 0.0) kc.gate_chi2 = o.gate;
    if (o.policy == "raw") {
      code = with_index<tf::Raw<double>>(o, {}, feed, args);
    } else if (o.policy == "average") {
      code = with_index<tf::Average<double>>(o, {}, feed, args);
    } else if (o.policy == "kalman") {
      code = with_index<tf::Kalman<double>>(o, kc, feed, args);
    } else {
      code = with_index<tf::Surfel<double>>(o, {.kalman = kc}, feed, args);
    }
    return code == 0 && !shortfall.empty() ? 1 : code;
  } catch (const std::invalid_argument& e) {  // a configuration the cloud refuses
    args.fail(e.what());
  }
}
