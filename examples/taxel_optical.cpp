// SPDX-License-Identifier: MIT
// taxel-optical: camera-based tactile sensors (GelSight and DIGIT class). `calibrate` turns
// ball presses into a calibration file; `depth` turns a frame into a height map in metres, its
// contact mask and contacts; `track` follows the marker dots as a displacement field.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <taxel/io/contacts_csv.hpp>
#include <taxel/io/npy.hpp>
#include <taxel/optical.hpp>
#include <tuple>
#include <vector>

#ifdef TAXEL_OPTICAL_HAVE_PNG
#include <taxel/io/png.hpp>
#endif
#ifdef TAXEL_OPTICAL_HAVE_JPEG
#include <taxel/io/jpeg.hpp>
#endif

#include "cli.hpp"
#include "report.hpp"

namespace {

namespace to = taxel::optical;

constexpr const char* kUsage =
    R"(usage: taxel-optical calibrate --ball-radius R --mm-per-pixel S [options] PRESS... -o CAL
       taxel-optical depth --calibration CAL [options] FRAME -o HEIGHT.npy
       taxel-optical track REFERENCE FRAME... [-o TRACKS.csv]

Camera-based tactile sensors (GelSight, DIGIT and their kin): a camera watches a lit gel, and
each frame's colour change says how the pressed surface slopes.

calibrate  builds the map from colour change to surface slope from frames of a ball pressed
           into the gel: each press's contact circle is found (and reported for review), the
           slopes inside follow from the ball's radius, and the map kept (lookup table or
           polynomial) is the one with the lower held-out error. CAL is JSON when its name ends
           in .json, taxel's binary .txcal otherwise; both keep the background frame.
  --ball-radius R       the ball's radius: a number with a unit (2mm, 0.002m) or a bare number
                        in millimetres, as --mm-per-pixel (a bare number below 0.1 is read as
                        metres: no calibration ball is that small)
  --mm-per-pixel S      the gel's size of one pixel [mm]
  --background BG       the frame without contact (default: the per-pixel median of the
                        presses, which needs presses at different places)
  --circles FILE        the contact circles to use instead of the ones found: one line per
                        press, "cx cy radius" in pixels (commas allowed; '#' comments)
  --threshold L         a contact changes colour by more than L levels (default 12)
  --table-bins N        lookup-table cells per channel (default 32)
  --no-markers          the gel has no marker dots

depth      reconstructs one frame: the colour change against the background, slopes through
           the calibration, their Poisson integration to heights.
  --calibration CAL     a file written by calibrate
  --background BG       the frame without contact (default: the one kept in CAL)
  --mask MASK.npy       also write the contact mask (uint8, 1 where touched: the gel's colour
                        changed and its height is at least --contact-share of the deepest)
  --contact-share F     (default 0.3; around a contact the gel drapes back to the flat,
                        deformed but not touched)
  --contacts C.csv      also write the contact mask's pixels as contacts (sensor frame: x along
                        the columns, y along the rows from the frame's centre, z = -height)
  --stride N            every N-th touched pixel each way gives a contact (default 4)
  --grow N              pixels added around the contact mask before integration (default 2)

track      follows the gel's marker dots from REFERENCE (the gel at rest) through the frames,
           in order: per frame the dots found, the tracks seen and lost, new tracks, and the
           displacement; -o writes every track of every frame as CSV (frame, track, x0, y0,
           x, y, dx, dy, seen; pixels). A lost dot stands where its neighbours' motion moves it.

Frames are PNG or JPEG files, NPY arrays of uint8 RGB (rows, cols, 3) or stacks (frames, rows,
cols, 3), or folders of PNG and JPEG files (in name order); - reads standard input.
HEIGHT.npy is a float64 array of the frame's rows x cols, metres, positive into the gel.

common options:
  --format text|json    the summary's format (default text)
  -h, --help            show this help
  --version             show taxel's version
Nothing is written unless every input was read and every step succeeded.
)";

[[noreturn]] void die(const std::string& why, int code = 2) {
  std::fprintf(stderr, "taxel-optical: %s\n", why.c_str());
  std::exit(code);
}

struct Options {
  std::string command;
  taxel_cli::Format format = taxel_cli::Format::text;
  double ball_radius = 0;  // [m]
  double pixel = 0;        // [m]
  std::string background, circles, calibration, output, mask, contacts;
  to::CalibrationOptions cal;
  int stride = 4;
  to::ReconstructOptions rec;
  std::vector<std::string> inputs;
};

// --ball-radius: a length with a unit, or a bare number in millimetres unless below 0.1.
double ball_radius(std::string_view text) {
  double v = 0;
  const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
  const bool bare = res.ec == std::errc() && res.ptr == text.data() + text.size();
  double metres = 0;
  if (bare) {
    metres = v >= 0.1 ? v * 1e-3 : v;
  } else if (!taxel_cli::parse_length(text, metres)) {
    die("--ball-radius '" + std::string(text) + "' is not a length (2mm, 0.002m or 2)");
  }
  if (!(metres >= 1e-5 && metres <= 0.5)) {
    die("--ball-radius " + std::string(text) + " is outside [0.01 mm, 0.5 m]");
  }
  return metres;
}

Options parse(int argc, char** argv) {
  if (argc < 2) die("no command: calibrate or depth (see --help)");
  const std::string_view first = argv[1];
  if (first == "-h" || first == "--help") {
    std::fputs(kUsage, stdout);
    std::exit(0);
  }
  Options o;
  o.command = std::string(first);
  if (o.command != "calibrate" && o.command != "depth" && o.command != "track") {
    die("unknown command '" + o.command + "': calibrate, depth or track (see --help)");
  }
  taxel_cli::Args args("taxel-optical", argc - 1, argv + 1);
  const bool cal = o.command == "calibrate", track = o.command == "track";
  const auto only = [&](bool ok, std::string_view a) {
    if (!ok) die(std::string(a) + " is not an option of " + o.command + " (see --help)");
  };
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--format") {
      o.format = taxel_cli::to_format(args.choice("text|json"));
    } else if (a == "-o") {
      o.output = std::string(args.value());
    } else if (a == "--background") {
      only(!track, a);
      o.background = std::string(args.value());
    } else if (a == "--ball-radius") {
      only(cal, a);
      o.ball_radius = ball_radius(args.value());
    } else if (a == "--mm-per-pixel") {
      only(cal, a);
      o.pixel = 1e-3 * args.number<double>(1e-6, 100.0);
    } else if (a == "--circles") {
      only(cal, a);
      o.circles = std::string(args.value());
    } else if (a == "--threshold") {
      only(cal, a);
      o.cal.threshold = args.number<double>(0.5, 255.0);
    } else if (a == "--table-bins") {
      only(cal, a);
      o.cal.table_bins = args.number<int>(4, 128);
    } else if (a == "--no-markers") {
      only(cal, a);
      o.cal.markers = false;
    } else if (a == "--calibration") {
      only(!cal && !track, a);
      o.calibration = std::string(args.value());
    } else if (a == "--mask") {
      only(!cal && !track, a);
      o.mask = std::string(args.value());
    } else if (a == "--contacts") {
      only(!cal && !track, a);
      o.contacts = std::string(args.value());
    } else if (a == "--stride") {
      only(!cal && !track, a);
      o.stride = args.number<int>(1, 1024);
    } else if (a == "--contact-share") {
      only(!cal && !track, a);
      o.rec.contact_share = args.number<double>(0.0, 0.999);
    } else if (a == "--grow") {
      only(!cal && !track, a);
      o.rec.grow = args.number<int>(0, 1024);
    } else if (a.size() > 1 && a[0] == '-') {
      die("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.inputs.emplace_back(a);
    }
  }
  if (o.output.empty() && !track) {
    die(o.command + " needs -o " + (cal ? "CAL" : "HEIGHT.npy"));
  }
  if (track) {
    if (o.inputs.size() < 2) die("track needs a reference frame and at least one more");
  } else if (cal) {
    if (!(o.ball_radius > 0)) die("calibrate needs --ball-radius R");
    if (!(o.pixel > 0)) die("calibrate needs --mm-per-pixel S");
    if (o.inputs.empty()) die("calibrate needs ball presses (PRESS...)");
    o.cal.ball_radius = o.ball_radius;
    o.cal.pixel = o.pixel;
  } else {
    if (o.calibration.empty()) die("depth needs --calibration CAL");
    if (o.inputs.size() != 1) die("depth takes one FRAME");
  }
  std::vector<std::string> read = o.inputs;
  for (const std::string* p : {&o.background, &o.circles, &o.calibration}) {
    if (!p->empty()) read.push_back(*p);
  }
  if (std::count(read.begin(), read.end(), "-") > 1) {
    die("only one input can be standard input (-)");
  }
  if (o.output == "-" || o.mask == "-" || o.contacts == "-") {
    die("outputs must be files (standard output carries the summary)");
  }
  for (const auto& [out, a1, a2] :
       {std::tuple{o.output, o.mask, o.contacts}, std::tuple{o.mask, o.output, o.contacts},
        std::tuple{o.contacts, o.output, o.mask}}) {
    if (out.empty()) continue;
    if (const std::string why = taxel_cli::output_conflict(out, read, {a1, a2}); !why.empty()) {
      die(why);
    }
  }
  return o;
}

// One named frame.
struct Frame {
  std::string name;
  to::RgbFrame frame;
};

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The frames of a file (by its first bytes: PNG, JPEG or NPY) or of a folder's PNG and JPEG
// files in name order.
void load_frames(const std::string& path, std::vector<Frame>& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path != "-" && fs::is_directory(path, ec)) {
    std::vector<std::string> files;
    for (const auto& entry : fs::directory_iterator(path)) {
      const std::string ext = lower(entry.path().extension().string());
      if (entry.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg")) {
        files.push_back(entry.path().string());
      }
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) throw taxel::IoError(path, "the folder holds no PNG or JPEG file");
    for (const std::string& f : files) load_frames(f, out);
    return;
  }
  const std::string bytes = taxel_cli::read_input(path);
  const std::string name = taxel_cli::input_name(path);
  const std::string_view b(bytes);
  if (b.starts_with("\x93NUMPY")) {
    std::vector<to::RgbFrame> frames = to::decode_npy_frames(b, name);
    for (std::size_t i = 0; i < frames.size(); ++i) {
      out.push_back(
          {frames.size() == 1 ? name : name + "[" + std::to_string(i) + "]", std::move(frames[i])});
    }
  } else if (b.starts_with("\x89PNG")) {
#ifdef TAXEL_OPTICAL_HAVE_PNG
    out.push_back({name, taxel::io::decode_png(b, name)});
#else
    throw taxel::IoError(name, "PNG input needs taxel-optical built with libpng");
#endif
  } else if (b.size() >= 2 && static_cast<unsigned char>(b[0]) == 0xFF &&
             static_cast<unsigned char>(b[1]) == 0xD8) {
#ifdef TAXEL_OPTICAL_HAVE_JPEG
    out.push_back({name, taxel::io::decode_jpeg(b, name)});
#else
    throw taxel::IoError(name, "JPEG input needs taxel-optical built with libjpeg");
#endif
  } else {
    throw taxel::IoError(name, "not a PNG, JPEG or NPY frame");
  }
}

to::RgbFrame load_one(const std::string& path, const char* what) {
  std::vector<Frame> frames;
  load_frames(path, frames);
  if (frames.size() != 1) {
    throw taxel::IoError(
        taxel_cli::input_name(path),
        std::string(what) + " must be one frame, not " + std::to_string(frames.size()));
  }
  return std::move(frames.front().frame);
}

// --circles: "cx cy radius" per line.
std::vector<to::Circle> read_circles(const std::string& path) {
  const std::string text = taxel_cli::read_input(path);
  const std::string name = taxel_cli::input_name(path);
  std::vector<to::Circle> out;
  std::size_t line_no = 0;
  for (std::size_t pos = 0; pos < text.size();) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (const auto hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::replace(line.begin(), line.end(), ',', ' ');
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    double v[3];
    int used = 0;
    if (std::sscanf(line.c_str(), "%lf %lf %lf %n", &v[0], &v[1], &v[2], &used) != 3 ||
        line.find_first_not_of(" \t\r", static_cast<std::size_t>(used)) != std::string::npos ||
        !(std::isfinite(v[0]) && std::isfinite(v[1]) && v[2] > 0 && std::isfinite(v[2]))) {
      throw taxel::IoError(name, "line " + std::to_string(line_no) +
                                     ": expected \"cx cy radius\" in pixels, radius > 0");
    }
    out.push_back({v[0], v[1], v[2]});
  }
  return out;
}

std::string calibrate(const Options& o) {
  std::vector<Frame> presses;
  for (const std::string& path : o.inputs) load_frames(path, presses);
  if (presses.size() < 2)
    die("calibrate needs at least two presses, got " + std::to_string(presses.size()), 1);
  std::vector<to::RgbFrame> frames;
  for (const Frame& f : presses) frames.push_back(f.frame);
  std::string background = "given";
  to::RgbFrame bg;
  if (!o.background.empty()) {
    bg = load_one(o.background, "the background");
  } else {
    if (frames.size() < 3) die("without --background, at least three presses are needed", 1);
    for (const to::RgbFrame& f : frames) {
      if (f.rows != frames[0].rows || f.cols != frames[0].cols) {
        die("the presses differ in size", 1);
      }
    }
    bg = to::median_background(frames);
    background = "median of " + std::to_string(frames.size()) + " presses";
  }
  const std::vector<to::Circle> circles =
      o.circles.empty() ? std::vector<to::Circle>{} : read_circles(o.circles);
  if (!circles.empty() && circles.size() != presses.size()) {
    die(o.circles + " has " + std::to_string(circles.size()) + " circles for " +
            std::to_string(presses.size()) + " presses",
        1);
  }
  const to::Calibration cal = to::calibrate(frames, bg, o.cal, circles);
  taxel_cli::Json report = {
      {"command", "calibrate"},
      {"output", o.output},
      {"presses", presses.size()},
      {"rows", cal.rows},
      {"cols", cal.cols},
      {"ball_radius_m", o.ball_radius},
      {"pixel_m", o.pixel},
      {"background", background},
      {"method", cal.method == to::Calibration::Method::polynomial ? "polynomial" : "lookup_table"},
      {"heldout_gradient_rms", cal.heldout()},
      {"heldout_polynomial", cal.heldout_polynomial},
      {"heldout_table", cal.heldout_table}};
  taxel_cli::Json list = taxel_cli::Json::array();
  for (std::size_t i = 0; i < presses.size(); ++i) {
    const to::Circle& c = cal.circles[i];
    list.push_back({{"file", presses[i].name},
                    {"cx", c.cx},
                    {"cy", c.cy},
                    {"radius_px", c.radius},
                    {"given", !circles.empty()}});
  }
  report["circles"] = std::move(list);
  taxel::io::write_file(o.output, lower(o.output).ends_with(".json")
                                      ? to::encode_calibration_json(cal)
                                      : to::encode_calibration(cal));
  return taxel_cli::render(report, o.format);
}

std::string depth(const Options& o) {
  to::Calibration cal = to::load_calibration(o.calibration);
  const to::RgbFrame frame = load_one(o.inputs.front(), "FRAME");
  if (!o.background.empty()) {
    const to::RgbFrame bg = load_one(o.background, "the background");
    if (bg.rows != cal.rows || bg.cols != cal.cols) {
      die(o.background + " is " + std::to_string(bg.rows) + " x " + std::to_string(bg.cols) +
              ", the calibration is for " + std::to_string(cal.rows) + " x " +
              std::to_string(cal.cols),
          1);
    }
    cal.background = to::colour_planes(bg);
    if (cal.markers) cal.background_markers = to::marker_mask(bg, cal.marker);
  }
  if (frame.rows != cal.rows || frame.cols != cal.cols) {
    die(taxel_cli::input_name(o.inputs.front()) + " is " + std::to_string(frame.rows) + " x " +
            std::to_string(frame.cols) + ", the calibration " + o.calibration + " is for " +
            std::to_string(cal.rows) + " x " + std::to_string(cal.cols),
        1);
  }
  to::PoissonSolver solver(cal.rows, cal.cols);
  const to::HeightMap map = to::reconstruct(frame, cal, solver, o.rec);
  const std::size_t shape[2] = {static_cast<std::size_t>(cal.rows),
                                static_cast<std::size_t>(cal.cols)};
  std::vector<std::pair<std::string, std::string>> outputs;
  outputs.emplace_back(o.output, taxel::io::encode_npy_f64(
                                     shape, {map.height.data(), std::size_t(map.height.size())}));
  std::size_t touched = 0, deformed = 0;
  double peak = 0;
  for (Eigen::Index i = 0; i < map.mask.size(); ++i) {
    deformed += map.mask.data()[i] != 0;
    touched += map.contact.data()[i] != 0;
    if (map.mask.data()[i]) peak = std::max(peak, map.height.data()[i]);
  }
  if (!o.mask.empty()) {
    outputs.emplace_back(o.mask, taxel::io::encode_npy_u8(
                                     shape, {map.contact.data(), std::size_t(map.contact.size())}));
  }
  std::size_t contacts = 0;
  if (!o.contacts.empty()) {
    // Each contact's normal is as uncertain as the calibration's held-out slope error, and its
    // height as that slope over its footprint.
    const double normal_sigma = std::max(cal.heldout(), 1e-3);
    std::vector<taxel::Contact<double>> out;
    contacts =
        to::height_contacts(map, cal.pixel, Eigen::Isometry3d::Identity(), 0.0,
                            normal_sigma * o.stride * cal.pixel, normal_sigma, o.stride, out);
    outputs.emplace_back(o.contacts, taxel::io::encode_contacts_csv(out));
  }
  taxel_cli::write_outputs(outputs);
  taxel_cli::Json report = {
      {"command", "depth"},        {"frame", taxel_cli::input_name(o.inputs.front())},
      {"output", o.output},        {"rows", cal.rows},
      {"cols", cal.cols},          {"deformed_pixels", deformed},
      {"touched_pixels", touched}, {"max_height_m", peak}};
  if (!o.contacts.empty()) report["contacts"] = contacts;
  return taxel_cli::render(report, o.format);
}

std::string track(const Options& o) {
  std::vector<Frame> frames;
  for (const std::string& path : o.inputs) load_frames(path, frames);
  if (frames.size() < 2) die("track needs a reference frame and at least one more", 1);
  const to::RgbFrame& ref = frames.front().frame;
  to::MarkerTracker tracker(to::find_dots(ref));
  const std::size_t reference_dots = tracker.tracks().size();
  std::string csv = "frame,track,x0,y0,x,y,dx,dy,seen\n";
  taxel_cli::Json list = taxel_cli::Json::array();
  for (std::size_t f = 1; f < frames.size(); ++f) {
    const to::RgbFrame& frame = frames[f].frame;
    if (frame.rows != ref.rows || frame.cols != ref.cols) {
      die(frames[f].name + " is " + std::to_string(frame.rows) + " x " +
              std::to_string(frame.cols) + ", the reference " + std::to_string(ref.rows) + " x " +
              std::to_string(ref.cols),
          1);
    }
    const std::size_t before = tracker.tracks().size();
    const std::vector<to::Dot> dots = to::find_dots(frame);
    const std::size_t seen = tracker.update(dots);
    std::size_t lost = 0;
    double sum = 0, largest = 0;
    for (std::size_t i = 0; i < tracker.tracks().size(); ++i) {
      const to::MarkerTrack& t = tracker.tracks()[i];
      if (!t.seen) ++lost;
      const double d = std::hypot(t.dx(), t.dy());
      if (t.seen) {
        sum += d;
        largest = std::max(largest, d);
      }
      taxel_cli::appendf(csv, "%zu,%zu,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%d\n", f, i, t.x0, t.y0, t.x,
                         t.y, t.dx(), t.dy(), t.seen ? 1 : 0);
    }
    list.push_back({{"frame", f},
                    {"file", frames[f].name},
                    {"dots", dots.size()},
                    {"seen", seen},
                    {"lost", lost},
                    {"new", tracker.tracks().size() - before},
                    {"mean_displacement_px", seen > 0 ? sum / double(seen) : 0.0},
                    {"max_displacement_px", largest}});
  }
  if (!o.output.empty()) taxel::io::write_file(o.output, csv);
  taxel_cli::Json report = {{"command", "track"},
                            {"reference", frames.front().name},
                            {"reference_dots", reference_dots},
                            {"max_step_px", tracker.max_step()}};
  report["frames"] = std::move(list);
  return taxel_cli::render(report, o.format);
}

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("taxel-optical");
  taxel_cli::print_version_if_asked("taxel-optical", argc, argv);
  const Options opt = parse(argc, argv);
  std::string summary = opt.command == "calibrate" ? calibrate(opt)
                        : opt.command == "depth"   ? depth(opt)
                                                   : track(opt);
  if (!summary.empty() && summary.back() != '\n') summary.push_back('\n');
  std::fwrite(summary.data(), 1, summary.size(), stdout);  // checked at exit
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "taxel-optical: %s\n", e.what());
  return 1;
}
