// SPDX-License-Identifier: MIT
// taxel-demo: everything taxel does, end to end, on simulated data, into one folder with an
// index.html that shows the tables and pictures (no server needed).
//   1. A simulated three-finger hand (two DSA-like 14x6 pads per finger) grasps, palpates and
//      slides over four objects; raw, averaging and Kalman fusion; accuracy/compaction table,
//      PLY clouds, cloud pictures and an error-against-contacts plot.
//   2. Recognition by ICP: Kalman clouds of grasped objects at random poses, recognised among a
//      library of six models; confusion matrix.
//   3. Pressure images (second paper): synthetic 32x32 palm grasps, segmentation and
//      reconstruction pictures, conventional against hybrid features by 5-fold CV.
//   4. A recorded DSACON32m session (data/sessions) replayed through the driver into fusion.
//   taxel-demo [--quick] [OUTPUT-FOLDER]      (default taxel-demo-output)
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <string_view>
#include <taxel/taxel.hpp>
#include <vector>
#if defined(TAXEL_DEMO_HAVE_PNG)
#include <taxel/io/png.hpp>
#endif
#if defined(TAXEL_DEMO_HAVE_DRIVERS)
#include <taxel/drivers/convert.hpp>
#include <taxel/drivers/dsacon_device.hpp>
#include <taxel/drivers/session.hpp>

#include "../drivers/examples/device_cli.hpp"
#endif

#include "cli.hpp"
#include "demo_viewer.hpp"
#include "explore_harness.hpp"
#include "report.hpp"

namespace {

using namespace taxel;
namespace fs = std::filesystem;
namespace tf = taxel::fusion;
namespace ti = taxel::image;
namespace tl = taxel::learn;
namespace tr = taxel::registration;

using Clock = std::chrono::steady_clock;

// Progress and tables: standard output, or standard error when --format asks for JSON or CSV
// there; the figures also go into `figures`.
FILE* say = stdout;
taxel_cli::Json figures = taxel_cli::Json::object();
double since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// The page: sections of tables, pictures and links, written at the end.
struct Page {
  std::string body;
  std::vector<std::string> images;
  void heading(const std::string& h) { body += "<h2>" + h + "</h2>\n"; }
  void para(const std::string& p) { body += "<p>" + p + "</p>\n"; }
  void table(const std::vector<std::string>& head,
             const std::vector<std::vector<std::string>>& rows) {
    body += "<table><tr>";
    for (const auto& h : head) body.append("<th>").append(h).append("</th>");
    body += "</tr>\n";
    for (const auto& r : rows) {
      body += "<tr>";
      for (const auto& c : r) body.append("<td>").append(c).append("</td>");
      body += "</tr>\n";
    }
    body += "</table>\n";
  }
  void figure(const std::string& file, const std::string& caption) {
    images.push_back(file);
    body.append("<figure><img src=\"").append(file).append("\" alt=\"").append(caption);
    body.append("\"><figcaption>").append(caption).append("</figcaption></figure>\n");
  }
  void raw(const std::string& html) { body += html; }
  // Links that download (PLY is binary: a browser would show it as text).
  void links(const std::vector<std::string>& files, const fs::path& dir) {
    body += "<p class=\"files\">PLY files (binary; MeshLab, CloudCompare, Open3D, taxel's io): ";
    for (const auto& f : files) {
      std::error_code ec;
      const auto bytes = fs::file_size(dir / f, ec);
      body.append("<a download href=\"").append(f).append("\">").append(f).append("</a>");
      if (!ec) body.append(" (").append(std::to_string((bytes + 1023) / 1024)).append(" KiB)");
      body += " ";
    }
    body += "</p>\n";
  }
  std::string html(const std::string& summary, const std::string& stamp) const {
    std::string h =
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
        "<title>taxel demo</title>\n<style>\n"
        "body{font-family:sans-serif;max-width:70em;margin:2em auto;padding:0 1em;color:#222}\n"
        "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:.25em "
        ".6em;"
        "text-align:right}th{background:#eee}figure{display:inline-block;margin:.5em;"
        "vertical-align:top}figcaption{font-size:.9em;color:#555;max-width:32em}"
        "img{max-width:100%;border:1px solid #ddd}.files a{margin-right:.8em;font-size:.9em}\n"
        ".checks{display:none}footer{color:#666;font-size:.85em;margin-top:2em;border-top:1px "
        "solid "
        "#ddd;padding-top:.5em}.labels{display:flex;gap:8px;font-size:.85em;margin-left:calc(.5em "
        "+ 1px)}"
        ".labels span{width:192px;text-align:center}\n"
        "</style></head><body>\n<h1>taxel: tactile perception, end to end</h1>\n<p>" +
        summary + "</p>\n" + taxel_demo::viewer_script() + body + "<footer>" + stamp +
        "</footer>\n<div class=\"checks\"><p id=\"image-check\">checking pictures...</p>"
        "<p id=\"view-check\">checking 3-D views...</p></div>\n"
        "<script>\n"
        "window.addEventListener('load', () => {\n"
        "  const imgs = Array.from(document.images);\n"
        "  const broken = imgs.filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src);\n"
        "  const p = document.getElementById('image-check');\n"
        "  p.textContent = broken.length ? 'broken pictures: ' + broken.join(' ')\n"
        "                                : 'all ' + imgs.length + ' pictures loaded';\n"
        "  p.dataset.status = broken.length ? 'broken' : 'ok';\n"
        "  const views = Array.from(document.querySelectorAll('canvas.cloud3d'));\n"
        "  views.forEach(c => { try { taxelView(c); } catch (e) { c.dataset.status = e; } });\n"
        "  const blank = views.filter(c => !(Number(c.dataset.inked) > 200)).map(c => c.id);\n"
        "  const v = document.getElementById('view-check');\n"
        "  v.textContent = blank.length ? 'blank 3-D views: ' + blank.join(' ')\n"
        "                               : views.length + ' 3-D views rendered';\n"
        "  v.dataset.status = blank.length ? 'blank' : 'ok';\n"
        "});\n</script>\n</body></html>\n";
    return h;
  }
};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

// Writes a picture as PNG (PPM without libpng; browsers do not show PPM) and returns its name.
std::string write_picture(const fs::path& dir, const std::string& stem, const io::RgbImage& pic) {
#if defined(TAXEL_DEMO_HAVE_PNG)
  const std::string name = stem + ".png";
  io::write_png((dir / name).string(), pic);
#else
  const std::string name = stem + ".ppm";
  io::write_file((dir / name).string(), io::encode_ppm(pic));
#endif
  return name;
}

// A horizontal colour bar of taxel's ramp, labelled at both ends.
std::string colour_bar(const std::string& what, const std::string& lo, const std::string& hi) {
  std::string stops;
  for (int k = 0; k <= 10; ++k) {
    const auto c = io::ramp(k / 10.0);
    stops += (k ? "," : "") + std::string("rgb(") + std::to_string(c[0]) + "," +
             std::to_string(c[1]) + "," + std::to_string(c[2]) + ")";
  }
  return "<div class=\"view3d\"><div class=\"bar\"><span>" + what + ": " + lo +
         "</span><div style=\"background:linear-gradient(to right," + stops + ")\"></div><span>" +
         hi + "</span></div></div>\n";
}

// ---- 1. fusion ---------------------------------------------------------------------------------

struct FusionRow {
  std::string object, policy;
  sim::ReconstructionMetrics m;
  double ns = 0.0;
};

template <class Policy, class Shape>
FusionRow fuse(const std::string& object, const char* policy, const Shape& truth,
               const std::vector<Contact<double>>& contacts, const fs::path& dir,
               PointCloud<double>* kept = nullptr) {
  tf::ContactCloud<Policy, index::VoxelHash<double>> cloud({.association_radius = 4e-3});
  const auto t0 = Clock::now();
  (void)cloud.insert(std::span<const Contact<double>>(contacts));
  FusionRow r{
      object, policy, {}, 1e9 * since(t0) / double(std::max<std::size_t>(1, contacts.size()))};
  PointCloud<double> pc = cloud.to_point_cloud();
  r.m = sim::reconstruction_metrics(truth, pc.points, contacts.size(), {.coverage_samples = 4000});
  io::write_ply((dir / (object + "_" + policy + ".ply")).string(), pc);
  if (kept != nullptr) *kept = std::move(pc);
  return r;
}

// The hand's contacts on one object: grasps, palpation and slides with per-tactel contacts.
template <class Shape>
std::vector<Contact<double>> explore(const Shape& shape, const Isometry3d& pose, bool quick,
                                     std::uint64_t seed) {
  sim::ExplorationConfig cfg;
  cfg.object_pose = pose;
  cfg.seed = seed;
  std::vector<Contact<double>> all;
  const auto add = [&](const auto& ex) {
    const auto c = ex.contacts();
    all.insert(all.end(), c.begin(), c.end());
  };
  add(sim::explore_grasps(shape, cfg, {.grasps = quick ? 4 : 10}));
  add(sim::explore_palpation(shape, cfg, {.touches = quick ? 15 : 40}));
  add(sim::explore_sliding(shape, cfg, {.slides = quick ? 2 : 4, .frames = quick ? 300u : 500u}));
  return all;
}

// The rotations that map an object onto itself, for pose errors that do not blame a symmetric
// object's arbitrary turn: a sphere any, a cylinder any about its axis and a half turn across
// it, a cone any about its axis, a box the half turns about its axes, a cube the 24 rotations
// of the cube.
enum class Symmetry { sphere, cylinder, cone, box, cube };

// The angle [deg] between R (identity when the pose is right) and the nearest symmetry; NaN for
// a sphere, whose rotation is not defined.
double rotation_error_deg(const Eigen::Matrix3d& R, Symmetry s) {
  const double deg = 180.0 / std::numbers::pi;
  const auto acos_deg = [&](double c) { return std::acos(std::clamp(c, -1.0, 1.0)) * deg; };
  switch (s) {
    case Symmetry::sphere:
      return std::numeric_limits<double>::quiet_NaN();
    case Symmetry::cone:
      return acos_deg(R(2, 2));
    case Symmetry::cylinder:
      return acos_deg(std::abs(R(2, 2)));
    default:
      break;
  }
  double best = 180.0;
  // Signed permutation matrices of determinant +1 (the cube's 24); a box keeps the diagonal 4.
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  for (const auto& p : perms) {
    if (s == Symmetry::box && !(p[0] == 0 && p[1] == 1)) continue;
    for (int signs = 0; signs < 8; ++signs) {
      Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
      for (int r = 0; r < 3; ++r) S(r, p[r]) = (signs >> r & 1) ? -1.0 : 1.0;
      if (S.determinant() < 0) continue;
      best = std::min(best, Eigen::AngleAxisd(R * S.transpose()).angle() * deg);
    }
  }
  return best;
}

struct Object {
  std::string name;
  Symmetry symmetry = Symmetry::sphere;
  std::function<std::vector<Contact<double>>(const Isometry3d&, bool, std::uint64_t)> explore;
  std::function<PointCloud<double>(std::size_t)> model;
  std::function<std::vector<FusionRow>(const std::vector<Contact<double>>&, const fs::path&,
                                       PointCloud<double>&)>
      fuse_all;
  std::function<std::vector<double>(const std::vector<Vec3d>&)> distances;
  std::function<std::vector<double>(const std::vector<Contact<double>>&, std::size_t)> curve;
};

template <class Shape>
Object make_object(std::string name, Shape shape, Symmetry symmetry) {
  Object o;
  o.name = name;
  o.symmetry = symmetry;
  o.explore = [shape](const Isometry3d& pose, bool quick, std::uint64_t seed) {
    return explore(shape, pose, quick, seed);
  };
  o.model = [shape](std::size_t n) { return sim::sample_surface(shape, n, 1); };
  o.fuse_all = [shape, name](const std::vector<Contact<double>>& c, const fs::path& dir,
                             PointCloud<double>& kalman) {
    return std::vector<FusionRow>{fuse<tf::Raw<double>>(name, "raw", shape, c, dir),
                                  fuse<tf::Average<double>>(name, "average", shape, c, dir),
                                  fuse<tf::Kalman<double>>(name, "kalman", shape, c, dir),
                                  fuse<tf::Surfel<double>>(name, "surfel", shape, c, dir, &kalman)};
  };
  o.distances = [shape](const std::vector<Vec3d>& pts) {
    std::vector<double> d;
    for (const auto& p : pts) d.push_back(1e3 * std::abs(shape.signed_distance(p)));
    return d;
  };
  // RMS error [mm] of raw, average, Kalman and Surfel after the first k contacts, k doubling.
  o.curve = [shape](const std::vector<Contact<double>>& c, std::size_t k) {
    std::vector<double> out;
    const std::vector<Contact<double>> head(c.begin(), c.begin() + long(std::min(k, c.size())));
    const auto rms = [&](auto&& cloud) {
      (void)cloud.insert(std::span<const Contact<double>>(head));
      return 1e3 * sim::surface_error(shape, cloud.to_point_cloud().points).rms;
    };
    out.push_back(rms(tf::ContactCloud<tf::Raw<double>>({.association_radius = 4e-3})));
    out.push_back(rms(tf::ContactCloud<tf::Average<double>>({.association_radius = 4e-3})));
    out.push_back(rms(tf::ContactCloud<tf::Kalman<double>>({.association_radius = 4e-3})));
    out.push_back(rms(tf::ContactCloud<tf::Surfel<double>>({.association_radius = 4e-3})));
    return out;
  };
  return o;
}

void fusion_section(const std::vector<Object>& objects, bool quick, const fs::path& out,
                    unsigned threads, Page& page) {
  std::fprintf(
      say,
      "\n1. Contact fusion: a three-finger hand (two 14x6 DSA-like pads per finger, 3.4 mm "
      "tactels, 12-bit readings) grasps, palpates and slides over each object\n");
  std::fprintf(say, "%-16s %-8s %8s %7s %8s %8s %8s %7s %8s %10s\n", "object", "policy", "contacts",
               "points", "compact", "mean mm", "rms mm", "max mm", "cover", "signed mm");
  // Every object's exploration, then every object's fusion and every checkpoint of the error
  // curve (on the second object's stream), as jobs on `threads` threads; each job fills its
  // own slot and the slots are reported in order, so the output does not depend on the
  // thread count.
  const std::size_t n = objects.size();
  std::vector<std::vector<Contact<double>>> streams(n);
  parallel_for(n, threads, [&](std::size_t i) {
    streams[i] = objects[i].explore(Isometry3d::Identity(), quick, 100 + i);
  });
  struct Fused {
    std::vector<FusionRow> rows;
    PointCloud<double> surfel;
    std::vector<double> error;  // of the Surfel points [mm]
  };
  std::vector<Fused> fused(n);
  const std::vector<Contact<double>>& curve_stream = streams[1];
  std::vector<std::size_t> checkpoints;
  for (std::size_t k = 500; k < curve_stream.size() * 2; k *= 2) checkpoints.push_back(k);
  std::vector<std::vector<double>> curve(checkpoints.size());
  parallel_for(n + checkpoints.size(), threads, [&](std::size_t j) {
    if (j < n) {
      Fused& f = fused[j];
      f.rows = objects[j].fuse_all(streams[j], out, f.surfel);
      f.error = objects[j].distances(f.surfel.points);
    } else {
      const std::size_t c = checkpoints.size() - 1 - (j - n);  // the longest first
      curve[c] = objects[1].curve(curve_stream, checkpoints[c]);
    }
  });
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> files, views;
  for (std::size_t i = 0; i < n; ++i) {
    const Object& o = objects[i];
    for (const FusionRow& r : fused[i].rows) {
      std::fprintf(say, "%-16s %-8s %8zu %7zu %7.1fx %8.3f %8.3f %8.2f %6.1f%% %+10.3f\n",
                   r.object.c_str(), r.policy.c_str(), r.m.contacts, r.m.points, r.m.compaction,
                   1e3 * r.m.error.mean, 1e3 * r.m.error.rms, 1e3 * r.m.error.max,
                   100.0 * r.m.coverage, 1e3 * r.m.error.signed_mean);
      figures["fusion"].push_back({{"object", r.object},
                                   {"policy", r.policy},
                                   {"contacts", r.m.contacts},
                                   {"points", r.m.points},
                                   {"mean_mm", 1e3 * r.m.error.mean},
                                   {"rms_mm", 1e3 * r.m.error.rms},
                                   {"max_mm", 1e3 * r.m.error.max},
                                   {"signed_mm", 1e3 * r.m.error.signed_mean},
                                   {"coverage", r.m.coverage}});
      rows.push_back({r.object, r.policy, std::to_string(r.m.contacts), std::to_string(r.m.points),
                      fmt("%.1fx", r.m.compaction), fmt("%.3f", 1e3 * r.m.error.mean),
                      fmt("%.3f", 1e3 * r.m.error.rms), fmt("%.2f", 1e3 * r.m.error.max),
                      fmt("%.1f %%", 100.0 * r.m.coverage),
                      fmt("%+.3f", 1e3 * r.m.error.signed_mean)});
      files.push_back(r.object + "_" + r.policy + ".ply");
    }
    const PointCloud<double>& surfel = fused[i].surfel;
    const std::vector<double>& err = fused[i].error;
    io::CloudView view;
    view.title = o.name + ": Surfel cloud, " + std::to_string(surfel.size()) + " points";
    view.value_label = "error mm";
    view.value_min = 0.0;
    io::write_file((out / (o.name + "_surfel.svg")).string(),
                   io::render_cloud_svg(surfel.points, err, view));
    // The colour scale: up to the 95th percentile of the errors (at least 0.05 mm).
    std::vector<double> sorted = err;
    std::sort(sorted.begin(), sorted.end());
    const double top = std::max(0.05, sorted.empty() ? 0.0 : sorted[sorted.size() * 95 / 100]);
    views.push_back(taxel_demo::view_html(
        "view-" + o.name,
        o.name + ": the Surfel-fused cloud (" + std::to_string(surfel.size()) +
            " points), coloured by its distance to the true surface; drag to turn, wheel to "
            "zoom (<a href=\"" +
            o.name + "_surfel.svg\">as SVG</a>)",
        {taxel_demo::ramp_layer(surfel.points, err, top)}, top, "mm and above"));
  }
  page.heading("1. Contact fusion: raw, averaging, Kalman and Surfel");
  page.para(
      "A simulated three-finger hand with two 14x6 tactile pads per finger (3.4 mm tactels, "
      "12-bit readings, 0.3 mm depth noise, 0.2 mm / 0.02 rad pose noise) grasps, palpates and "
      "slides over each object. Every active tactel gives a contact with its local surface "
      "normal (from the pad's depth map) and an anisotropic covariance tight along it, fused "
      "with a 4 mm association gate. Surfel, the default, is a Kalman point that fits the "
      "curvature of its patch and removes the chord sag that averaging suffers. Errors are "
      "distances of the fused points to the true surface (signed: outside minus inside); "
      "coverage is the share of the surface within 5 mm of a point (sensor/, sim/, fusion/).");
  page.table({"object", "policy", "contacts", "points", "compaction", "mean mm", "RMS mm", "max mm",
              "coverage", "signed mm"},
             rows);
  for (const std::string& v : views) page.raw(v);
  // Error against contacts, for the second object.
  io::LinePlot plot;
  plot.title = "RMS error against contacts (" + objects[1].name + ")";
  plot.x_label = "contacts (thousands)";
  plot.y_label = "RMS distance to the surface (mm)";
  plot.y_min = 0.0;
  plot.series = {{"raw", {}, {}}, {"average", {}, {}}, {"kalman", {}, {}}, {"surfel", {}, {}}};
  for (std::size_t c = 0; c < checkpoints.size(); ++c) {
    for (std::size_t s = 0; s < plot.series.size(); ++s) {
      plot.series[s].x.push_back(double(std::min(checkpoints[c], curve_stream.size())) / 1000.0);
      plot.series[s].y.push_back(curve[c][s]);
    }
  }
  io::write_file((out / "error_vs_contacts.svg").string(), io::render_svg(plot));
  page.figure("error_vs_contacts.svg", "RMS error of the four policies as contacts accumulate");
  page.links(files, out);
}

// ---- 2. recognition ------------------------------------------------------------------------

void recognition_section(const std::vector<Object>& objects, bool quick, unsigned threads,
                         Page& page) {
  tr::LibraryConfig config;
  config.threads = threads;
  tr::ObjectLibrary<double> lib(config);
  for (const auto& o : objects) lib.add(o.name, o.model(8000));
  const int trials = quick ? 1 : 3;
  const std::size_t n = objects.size();
  std::vector<std::vector<int>> confusion(n, std::vector<int>(n + 1, 0));
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  double seconds = 0.0;
  int right = 0;
  std::vector<std::vector<std::string>> pose_rows;
  std::vector<std::string> views;
  for (int t = 0; t < trials; ++t) {
    for (std::size_t o = 0; o < n; ++o) {
      Isometry3d pose = Isometry3d::Identity();
      pose.linear() =
          Eigen::Quaterniond(Eigen::Vector4d(g(rng), g(rng), g(rng), g(rng)).normalized())
              .toRotationMatrix();
      pose.translation() = 0.05 * Vec3d(g(rng), g(rng), g(rng));
      // A short exploration (the quick one) at that pose, fused by Kalman filters.
      tf::ContactCloud<tf::Kalman<double>> cloud({.association_radius = 4e-3});
      const auto contacts = objects[o].explore(pose, true, 1000 + 10 * std::uint64_t(t) + o);
      (void)cloud.insert(std::span<const Contact<double>>(contacts));
      const auto t0 = Clock::now();
      const tr::ObjectRecognition r = lib.recognize(cloud.to_point_cloud());
      seconds += since(t0);
      std::size_t answer = n;
      for (std::size_t k = 0; k < n && !r.unknown; ++k)
        answer = objects[k].name == r.best ? k : answer;
      ++confusion[o][answer];
      right += answer == o ? 1 : 0;
      // The pose: T_model_cloud maps the cloud (in the world) onto the model, so composed with
      // the object's true pose it is a symmetry of the object when right.
      const tr::ModelMatch& top = r.ranking.front();
      if (top.name == objects[o].name) {
        const Isometry3d err = top.transform * pose;
        const double centre_mm = 1e3 * err.translation().norm();
        const double rot = rotation_error_deg(err.linear(), objects[o].symmetry);
        pose_rows.push_back({objects[o].name, std::to_string(t + 1), r.unknown ? "unknown" : r.best,
                             fmt("%.2f", 1e3 * top.score), fmt("%.2f", centre_mm),
                             std::isnan(rot) ? "any (sphere)" : fmt("%.2f", rot)});
      } else {
        pose_rows.push_back({objects[o].name, std::to_string(t + 1), r.unknown ? "unknown" : r.best,
                             fmt("%.2f", 1e3 * top.score), "-", "-"});
      }
      if (t == 0) {  // the cloud on the model it was recognised as
        std::size_t shown = o;
        for (std::size_t k = 0; k < n; ++k) shown = objects[k].name == top.name ? k : shown;
        const PointCloud<double> aligned = transformed(cloud.to_point_cloud(), top.transform);
        views.push_back(taxel_demo::view_html(
            "recognised-" + objects[o].name,
            objects[o].name + " at a random pose, recognised as " + top.name +
                ": its fused cloud (red) mapped by the recognised pose onto the model (grey)",
            {taxel_demo::plain_layer(objects[shown].model(8000).points, {150, 150, 150}, 4000,
                                     2.0f),
             taxel_demo::plain_layer(aligned.points, {220, 40, 30}, 100000, 4.0f)}));
      }
    }
  }
  const int total = trials * int(n);
  std::fprintf(say,
               "\n2. Recognition by ICP among %zu models, %d trial(s) per object at random poses\n",
               n, trials);
  std::vector<std::string> head{"true \\ answer"};
  for (const auto& o : objects) head.push_back(o.name);
  head.push_back("unknown");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t o = 0; o < n; ++o) {
    std::fprintf(say, "%-16s", objects[o].name.c_str());
    std::vector<std::string> row{objects[o].name};
    for (std::size_t k = 0; k <= n; ++k) {
      std::fprintf(say, " %3d", confusion[o][k]);
      row.push_back(std::to_string(confusion[o][k]));
    }
    std::fprintf(say, "\n");
    rows.push_back(row);
  }
  std::fprintf(say, "top-1 %d / %d, %.1f ms per recognition\n", right, total,
               1e3 * seconds / total);
  figures["recognition"] = {
      {"right", right}, {"total", total}, {"ms_per_cloud", 1e3 * seconds / total}};
  page.heading("2. Recognising objects by touch (ICP)");
  page.para(
      "Each object is explored by the hand at a random pose, its contacts fused by Kalman "
      "filters, and the cloud matched against a library of the " +
      std::to_string(n) +
      " models by multi-start point-to-plane ICP (registration/object_library.hpp). "
      "Top-1: " +
      std::to_string(right) + " / " + std::to_string(total) + ", " +
      fmt("%.1f", 1e3 * seconds / total) + " ms per recognition.");
  page.table(head, rows);
  page.para(
      "The recognised poses against the true ones: where the object's origin lands (centre "
      "error) and the rotation error, up to the object's symmetries (any turn of a sphere, "
      "turns of a cylinder or cone about its axis, half turns of a box, the 24 turns of a "
      "cube).");
  page.table({"object", "trial", "answer", "score mm", "centre error mm", "rotation error deg"},
             pose_rows);
  for (const std::string& v : views) page.raw(v);
}

// ---- 3. pressure images ----------------------------------------------------------------------

void image_section(bool quick, const fs::path& out, unsigned threads, Page& page) {
  // The full run is the size of the paper's data set (and of 06_recognition_study): 25 subjects
  // x 4 classes x 20 grasps x 2 hands = 4000 images.
  const sim::PalmGraspSynth synth({}, 1);
  const auto data = synth.dataset(quick ? 6 : 25, quick ? 5 : 20);
  ti::Recognizer<> rec(32, 32);
  tl::Dataset conv, hyb;
  conv.x.resize(Eigen::Index(data.size()), ti::kRegionalFeatures);
  hyb.x.resize(Eigen::Index(data.size()), 32 * 32 + ti::kRegionalFeatures);
  std::vector<io::RgbImage> rows;
  std::vector<bool> shown(5, false);
  // The whole chain on every image, on `threads` threads (each with its own recogniser).
  const std::vector<ti::Recognition> all = ti::recognize_all(
      rec, data.size(), [&](std::size_t i) -> const auto& { return data[i].image; }, threads);
  for (std::size_t i = 0; i < data.size(); ++i) {
    const ti::Recognition& r = all[i];
    if (!r.ok()) throw std::runtime_error("image " + std::to_string(i) + ": " + r.message);
    conv.x.row(Eigen::Index(i)) = r.regional.transpose();
    hyb.x.row(Eigen::Index(i)) = r.hybrid.transpose();
    for (auto* d : {&conv, &hyb}) {
      d->y.push_back(int(data[i].label));
      d->groups.push_back(data[i].subject);
    }
    const auto label = std::size_t(data[i].label);
    if (!shown[label]) {  // one picture row per class: image | segmentation | HPRs | height map
      shown[label] = true;
      (void)rec.recognize(data[i].image);  // again, for its segmentation and reconstruction
      const ti::Segmentation& seg = rec.segmentation();
      ti::Image<std::uint8_t> hpr = seg.high;
      rows.push_back(io::side_by_side(
          {io::colorize(data[i].image, 0, 255, 6), io::colorize_classes(seg.classes, 6),
           io::colorize_classes(hpr * std::uint8_t{2}, 6),
           io::colorize(rec.reconstruction(), 0, std::max(1e-9, rec.reconstruction().maxCoeff()),
                        6)}));
    }
  }
  const std::string picture = write_picture(out, "pressure_images", io::stacked(rows));
  tl::LinearSvmConfig c;
  c.C = 0.01;
  const auto cv = [&](const tl::Dataset& d) {
    tl::CvOptions opt;
    opt.seed = 1;
    opt.threads = threads;
    const tl::CvReport r = tl::cross_validate(
        tl::Scaled<tl::StandardScaler, tl::LinearSvm>(tl::LinearSvm(c)), d.view(), opt);
    return 100.0 * r.accuracy;
  };
  const double a_conv = cv(conv), a_hyb = cv(hyb);
  std::fprintf(say,
               "\n3. Pressure images: %zu synthetic 32x32 palm grasps, 4 classes; linear SVM, "
               "5-fold CV\n   conventional (11 region descriptors) %.1f %%, hybrid (reconstruction "
               "gradients + descriptors) %.1f %%\n",
               data.size(), a_conv, a_hyb);
  figures["images"] = {
      {"images", data.size()}, {"conventional", a_conv / 100}, {"hybrid", a_hyb / 100}};
  page.heading("3. Pressure images: segmentation, reconstruction, recognition");
  page.para(
      "Synthetic 32x32 palm-grasp images of planar, one-edged, two-edged and cylindrical "
      "objects (sim/palm_grasp.hpp; the paper's data are not public). Each goes through "
      "1-D k-means segmentation, high-pressure regions, region descriptors, the edged / "
      "edgeless decision and the 3-D reconstruction (image/). " +
      std::to_string(data.size()) + " images, linear SVM, stratified 5-fold cross-validation:");
  page.table({"features", "accuracy"},
             {{"conventional: 11 region descriptors", fmt("%.1f %%", a_conv)},
              {"hybrid: reconstruction gradients + descriptors", fmt("%.1f %%", a_hyb)}});
  page.raw(
      "<div class=\"labels\"><span>pressure (0-255)</span><span>k-means: background (black), "
      "low (grey), high (white)</span><span>high-pressure regions (white)</span><span>3-D "
      "reconstruction: height (RecEdged / RecEdgeless)</span></div>\n");
  page.figure(picture,
              "one image per class, rows top to bottom: planar, one-edged, two-edged, "
              "cylindrical; 32 x 32 tactels, 6 pixels each");
  page.raw(colour_bar("pressure reading", "0", "255") +
           colour_bar("reconstructed height, per image", "0", "its maximum"));
}

// ---- 4. a recorded session --------------------------------------------------------------------

void session_section(const fs::path& out, Page& page) {
#if defined(TAXEL_DEMO_HAVE_DRIVERS)
  namespace td = taxel::drivers;
  const std::string dir = TAXEL_SESSION_DIR;
  td::DsaconDevice dev(td::ReplayTransport::from_file(dir + "/cylinder_grasp.session"),
                       {.reply_timeout = td::Timeout(50), .frame_timeout = td::Timeout(50)});
  dev.open();
  const std::string poses_file = dir + "/cylinder_grasp_poses.csv";
  const td::SessionPoses table(io::read_file(poses_file), poses_file, dev.matrices().size());
  const std::vector<Eigen::Isometry3d> fixed = td::static_matrix_poses(dev.matrices());
  std::vector<Eigen::Isometry3d> poses;
  dev.start();
  tf::ContactCloud<tf::Kalman<double>> cloud({.association_radius = 4e-3});
  std::vector<Contact<double>> contacts;
  std::size_t frames = 0, total = 0;
  io::RgbImage busiest;
  std::size_t busiest_contacts = 0;
  while (auto f = dev.read_frame()) {
    ++frames;
    if (!table.frame_poses(*f, fixed, td::PadCalibration{}.threshold, poses_file, poses)) continue;
    contacts.clear();
    td::frame_contacts(*f, dev.matrices(), poses, contacts);
    (void)cloud.insert(std::span<const Contact<double>>(contacts));
    total += contacts.size();
    if (contacts.size() > busiest_contacts) {  // picture of the frame with the most contact
      busiest_contacts = contacts.size();
      std::vector<io::RgbImage> panels;
      for (std::size_t m = 0; m < f->matrices.size(); ++m)
        panels.push_back(io::colorize(td::frame_image(*f, m), 0, 4095, 10));
      busiest = io::side_by_side(panels);
    }
  }
  const auto stats = dev.stats();
  dev.close();
  io::write_ply((out / "session_cloud.ply").string(), cloud.to_point_cloud());
  std::fprintf(say,
               "\n4. Recorded DSACON32m session replayed through the driver: %zu frames (%llu "
               "dropped), %zu contacts fused into %zu points\n",
               frames, static_cast<unsigned long long>(stats.dropped_frames), total, cloud.size());
  figures["session"] = {{"frames", frames},
                        {"dropped", stats.dropped_frames},
                        {"contacts", total},
                        {"points", cloud.size()}};
  page.heading("4. A recorded DSACON32m session through the driver");
  page.para(
      "data/sessions/cylinder_grasp.session: a simulated grasp of a cylinder streamed by the "
      "emulated DSACON32m controller and recorded byte for byte (taxel-record). Replayed "
      "through DsaconDevice: " +
      std::to_string(frames) + " frames, " + std::to_string(stats.dropped_frames) + " dropped, " +
      std::to_string(total) + " contacts fused into " + std::to_string(cloud.size()) + " points.");
  if (busiest_contacts > 0) {
    page.figure(write_picture(out, "session_frame", busiest),
                "the frame with the most contact: the six 14x6 matrices (0 to 5, left to "
                "right; rows top to bottom), readings 0-4095");
    page.raw(colour_bar("reading", "0", "4095"));
  }
  page.links({"session_cloud.ply"}, out);
#else
  (void)out;
  std::fprintf(say, "\n4. (drivers not built: no session replay; build with libusb-1.0-0-dev)\n");
  page.heading("4. A recorded DSACON32m session");
  page.para("Not run: taxel was built without its drivers (they need libusb-1.0-0-dev).");
#endif
}

// ---- 5. a camera-based tactile sensor ---------------------------------------------------------

void optical_section(bool quick, const fs::path& out, Page& page) {
  namespace to = taxel::optical;
  // A GelSight-Mini-like sensor rendered: 240 x 320 pixels of 0.0634 mm, marker dots, a 2 mm
  // calibration ball.
  const int rows = 240, cols = 320;
  const double pixel = 0.0634e-3, ball = 2e-3;
  to::ShadingModel model;
  const to::Colour lit = to::render_background(model, rows, cols);
  const std::vector<Eigen::Vector2d> dots = sim::marker_grid(rows, cols, 24.0);
  std::mt19937_64 rng(5);
  const auto render = [&](const sim::GelPress& g) {
    to::RgbFrame f = to::render(g.gx, g.gy, lit, model, 2.0, rng);
    sim::draw_markers(f, dots, 3.0, 0.7);
    return f;
  };
  const to::Plane zero = to::Plane::Zero(rows, cols);
  const to::RgbFrame background = render({zero, zero, zero});
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<to::RgbFrame> presses;
  const int count = quick ? 6 : 12;
  for (int i = 0; i < count; ++i) {
    presses.push_back(render(sim::press_ball(rows, cols, pixel, ball, 0.3e-3 + 0.4e-3 * u(rng),
                                             50 + 220 * u(rng), 50 + 140 * u(rng))));
  }
  const to::Calibration cal =
      to::calibrate(presses, background, {.ball_radius = ball, .pixel = pixel});
  // A held-out press, reconstructed.
  const sim::GelPress held = sim::press_ball(rows, cols, pixel, ball, 0.5e-3, 170, 110);
  const to::RgbFrame frame = render(held);
  to::PoissonSolver solver(rows, cols);
  const to::HeightMap map = to::reconstruct(frame, cal, solver);
  const to::BallFit fit = to::fit_ball(map, pixel);
  double e2 = 0, n = 0;
  for (int r = 0; r < rows; ++r) {
    for (int c = 0; c < cols; ++c) {
      if (held.height(r, c) <= 0) continue;
      e2 += (map.height(r, c) - held.height(r, c)) * (map.height(r, c) - held.height(r, c));
      n += 1;
    }
  }
  const double height_rms = std::sqrt(e2 / n);
  // The sensor pressed 0.4 mm deep along a 15 mm sphere, every frame fused (Surfel).
  const double R = 15e-3, depth = 0.4e-3;
  const sim::Sphere sphere(R);
  const int frames = quick ? 24 : 90;
  tf::ContactCloud<tf::Surfel<double>> cloud({.association_radius = 1e-3});
  std::vector<Contact<double>> contacts;
  std::size_t total = 0;
  for (int k = 0; k < frames; ++k) {
    const double a = 0.9 * std::numbers::pi * k / frames;
    const Vec3d normal(std::cos(a), 0.0, std::sin(a));
    const to::RgbFrame f =
        render(sim::press_ball(rows, cols, pixel, R, depth, 0.5 * (cols - 1), 0.5 * (rows - 1)));
    const to::HeightMap m = to::reconstruct(f, cal, solver);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const Vec3d z = -normal, y = Vec3d::UnitY();
    T.linear().col(0) = y.cross(z);
    T.linear().col(1) = y;
    T.linear().col(2) = z;
    T.translation() = -T.linear() * Vec3d(0.0, 0.0, R - depth);
    contacts.clear();
    total += to::height_contacts(m, pixel, T, 0.01 * k, 0.01e-3, std::max(cal.heldout(), 1e-3), 4,
                                 contacts);
    (void)cloud.insert(std::span<const Contact<double>>(contacts));
  }
  const PointCloud<double> pc = cloud.to_point_cloud();
  const sim::SurfaceError err = sim::surface_error(sphere, pc.points);
  io::write_ply((out / "optical_cloud.ply").string(), pc);
  std::fprintf(say,
               "\n5. Camera-based sensor (rendered GelSight-class frames): held-out slope error "
               "%.3f (%s), held-out ball radius %.3f mm (true 2.000), heights %.4f mm RMS; %d "
               "frames along a 15 mm sphere -> %zu points, %.4f mm RMS\n",
               cal.heldout(),
               cal.method == to::Calibration::Method::polynomial ? "polynomial" : "lookup table",
               1e3 * fit.radius, 1e3 * height_rms, frames, pc.size(), 1e3 * err.rms);
  figures["optical"] = {{"presses", count},
                        {"heldout_slope_rms", cal.heldout()},
                        {"ball_radius_m", fit.radius},
                        {"height_rms_m", height_rms},
                        {"sliding_frames", frames},
                        {"sliding_contacts", total},
                        {"sliding_points", pc.size()},
                        {"sliding_rms_m", err.rms},
                        {"sliding_signed_m", err.signed_mean}};
  page.heading("5. A camera-based tactile sensor (GelSight class)");
  page.para(
      "Frames rendered with a shading model of the published kind (a polynomial in the slope per "
      "colour channel), marker dots and noise, 240 x 320 pixels of 0.0634 mm. Calibrated from " +
      std::to_string(count) +
      " presses of a 2 mm ball (optical/), then a held-out press "
      "reconstructed, and the sensor pressed along a 15 mm sphere with every frame's contacts "
      "fused through its pose:");
  page.table(
      {"measure", "value"},
      {{"held-out slope error (map kept)", fmt("%.3f", cal.heldout())},
       {"held-out ball: fitted radius", fmt("%.3f mm (true 2.000)", 1e3 * fit.radius)},
       {"held-out ball: heights", fmt("%.4f mm RMS", 1e3 * height_rms)},
       {"sliding over the sphere: fused points", std::to_string(pc.size())},
       {"sliding over the sphere: error",
        fmt("%.4f mm RMS, ", 1e3 * err.rms) + fmt("%+.4f mm signed", 1e3 * err.signed_mean)}});
  page.raw(
      "<div class=\"labels\"><span>the frame</span><span>height (0 to its maximum)</span>"
      "<span>contact mask (white)</span></div>\n");
  image::Image<std::uint8_t> contact = map.contact * std::uint8_t{2};
  page.figure(write_picture(
                  out, "optical_press",
                  io::side_by_side(
                      {frame, io::colorize(map.height, 0, std::max(1e-9, map.height.maxCoeff()), 1),
                       io::colorize_classes(contact, 1)})),
              "a held-out ball press: the rendered frame, its heights and its contact mask");
  page.links({"optical_cloud.ply"}, out);
}

// Active touch: a box explored by chosen touches; the estimate coloured by its uncertainty.
void active_touch_section(bool quick, const fs::path& out, Page& page) {
  taxel_explore::Settings st;
  st.touches = quick ? 4 : 8;
  st.seed = 3;
  taxel_explore::TouchRecord last;
  std::vector<std::vector<std::string>> rows;
  const sim::Box box(Vec3d(0.04, 0.03, 0.02));
  (void)taxel_explore::explore(
      taxel_explore::AnyShape::of(box), st, [&](taxel_explore::TouchRecord& r) {
        rows.push_back({std::to_string(r.touch), std::to_string(r.contacts),
                        fmt("%.2f", 1e3 * r.surface_rms), fmt("%.0f %%", 100.0 * r.coverage),
                        fmt("%.2f", 1e3 * r.mean_std)});
        figures["active_touch"].push_back({{"touch", r.touch},
                                           {"surface_rms_m", r.surface_rms},
                                           {"coverage", r.coverage},
                                           {"mean_std_m", r.mean_std}});
        last = r;
      });
  const shape::SurfaceMesh& est = last.estimate;
  io::write_ply((out / "active_touch_estimate.ply").string(), est.to_point_cloud(),
                io::PlyFormat::binary_little_endian, est.mesh.triangles);
  page.heading("6. Active touch: the surface between touches, with its uncertainty");
  page.para(
      "A box (80 x 60 x 40 mm) at a random pose, poked " + std::to_string(st.touches) +
      " times by the pad along the approach rays the active policy chose: each touch goes where "
      "its predicted contact most lowers the estimate's variance. The contacts are fused "
      "(Surfel) into a Gaussian-process implicit surface (shape/); the mesh below is its zero "
      "level, each vertex coloured by its posterior standard deviation. Surface error: the "
      "symmetric RMS distance between the estimate and the true box.");
  page.table({"touch", "contacts", "surface RMS mm", "coverage", "mean std mm"}, rows);
  std::vector<double> sigma_mm;
  for (const double v : est.sigma) sigma_mm.push_back(1e3 * v);
  page.raw(taxel_demo::view_html(
      "view-active-touch",
      "the estimated box after " + std::to_string(st.touches) +
          " touches, coloured by its standard deviation; drag to turn, wheel to zoom",
      {taxel_demo::ramp_layer(est.mesh.vertices, sigma_mm, 5.0)}, 5.0, "mm and above"));
  page.links({"active_touch_estimate.ply"}, out);
}

std::string compiler() {
#if defined(__clang__)
  return "clang " __clang_version__;
#elif defined(__GNUC__)
  return "g++ " __VERSION__;
#else
  return "an unknown compiler";
#endif
}

// The time of the run, UTC, as 2026-01-31 12:00 UTC.
std::string run_time() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%d %H:%M UTC", &utc);
  return buf;
}

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("taxel-demo");
  taxel_cli::print_version_if_asked("taxel-demo", argc, argv);
  bool quick = false;
  unsigned threads = 0;
  taxel_cli::Format format = taxel_cli::Format::text;
  fs::path out = "taxel-demo-output";
  taxel_cli::Args args("taxel-demo", argc, argv);
  std::string_view a;
  bool have_out = false;
  while (args.next(a)) {
    if (a == "--quick") {
      quick = true;
    } else if (a == "--format") {
      format = taxel_cli::to_format(args.choice("text|json|csv"));
      say = format == taxel_cli::Format::text ? stdout : stderr;
    } else if (a == "--threads") {
      threads = args.number<unsigned>(0, 4096);
    } else if (a == "-h" || a == "--help") {
      std::puts(
          "usage: taxel-demo [--quick] [--format text|json|csv] [--threads N] [--version]\n"
          "                  [OUTPUT-FOLDER]\n"
          "Runs taxel end to end on simulated data and writes tables, PLY clouds,\n"
          "pictures and an index.html into OUTPUT-FOLDER (default taxel-demo-output).\n"
          "--format json prints the figures as one JSON document on standard output (csv: the\n"
          "fusion table), the progress going to standard error. --threads N runs the fusion\n"
          "and recognition work on N threads (default 0: every core); the figures are the same\n"
          "for any N.");
      return 0;
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else if (!have_out) {
      out = std::string(a);
      have_out = true;
    } else {
      args.fail("expected one OUTPUT-FOLDER, got a second: '" + std::string(a) + "'");
    }
  }
  fs::create_directories(out);
  const auto t0 = Clock::now();
  std::fprintf(say, "taxel-demo%s: output in %s\n", quick ? " (quick)" : "", out.c_str());
  const std::vector<Object> objects{
      make_object("sphere-40", sim::Sphere(0.04), Symmetry::sphere),
      make_object("cylinder-30x100", sim::Cylinder(0.03, 0.05), Symmetry::cylinder),
      make_object("box-80x60x40", sim::Box(Vec3d(0.04, 0.03, 0.02)), Symmetry::box),
      make_object("cone-30x60", sim::Cone(0.03, 0.06), Symmetry::cone),
      make_object("cube-50", sim::Box(Vec3d(0.025, 0.025, 0.025)), Symmetry::cube),
      make_object("sphere-25", sim::Sphere(0.025), Symmetry::sphere),
  };
  Page page;
  const std::vector<Object> fused(objects.begin(), objects.begin() + 4);
  fusion_section(fused, quick, out, threads, page);
  recognition_section(objects, quick, threads, page);
  image_section(quick, out, threads, page);
  session_section(out, page);
  optical_section(quick, out, page);
  active_touch_section(quick, out, page);
  const double seconds = since(t0);
  io::write_file(
      (out / "index.html").string(),
      page.html("Everything below was computed by <code>taxel-demo" +
                    std::string(quick ? " --quick" : "") + "</code> in " + fmt("%.0f", seconds) +
                    " s on simulated data; each section names the headers it uses. The 3-D "
                    "views turn when dragged (axes in millimetres); the clouds are also PLY "
                    "files, the pictures SVG and PNG.",
                "taxel " TAXEL_VERSION_STRING " &middot; taxel-demo" +
                    std::string(quick ? " --quick" : "") +
                    ", built " __DATE__ " " __TIME__ " with " + compiler() + " &middot; run " +
                    run_time() + " in " + fmt("%.0f", seconds) + " s"));
  std::fprintf(say, "\ndone in %.0f s; open %s\n", seconds, (out / "index.html").c_str());
  if (format != taxel_cli::Format::text) {
    figures["version"] = TAXEL_VERSION_STRING;
    figures["seconds"] = seconds;
    figures["page"] = (out / "index.html").string();
    const std::string text =
        taxel_cli::render(format == taxel_cli::Format::json ? figures : figures["fusion"], format);
    std::fwrite(text.data(), 1, text.size(), stdout);
  }
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "taxel-demo: %s\n", e.what());
  return 1;
}
