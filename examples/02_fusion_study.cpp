// SPDX-License-Identifier: MIT
// 02: the first paper's claim, checked on simulated explorations: probabilistic fusion gives a
// more accurate compact cloud than averaging, and both compress the raw cloud (Meier et al.
// 2011). Raw, Average, Kalman and Surfel (Kalman aware of the surface's curvature, the default).
// For a sphere, a cylinder, a box, a cone, a triangle mesh (an icosphere written to and read
// back from PLY), an ellipsoid and a torus, the same sliding streams, with anisotropic pad noise,
// go through Raw, Average and Kalman fusion; the table gives points, compaction, mean / RMS / max
// distance to the true surface and coverage. A control run with isotropic, constant noise shows
// Kalman and Average equal, as the theory says. Writes every cloud as PLY and a plot of RMS error
// against the number of contacts.
//   ./02_fusion_study [--quick] [--out DIR]
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <taxel/taxel.hpp>
#include <vector>

#include "cli.hpp"

namespace {

using namespace taxel;
namespace tf = taxel::fusion;

using taxel_cli::appendf;

struct Row {
  sim::ReconstructionMetrics m;
  sim::SurfaceError confirmed;  // points seen at least 5 times
  std::size_t confirmed_points = 0;
  sim::SurfaceError sparse;  // the other points: one to four contacts
  std::size_t sparse_points = 0;
  sim::SurfaceError supported;  // confident points (>= 3 contacts, sigma across <= 0.3 mm)
  // The points of 20-99 contacts and of 100 or more, and how many.
  sim::SurfaceError mid, many;
  std::size_t mid_points = 0, many_points = 0;
  // The angle [rad] between each point's normal (when the policy gives normals) and the true
  // surface normal at the point, over the points of at least 5 contacts: median and 90th
  // percentile. For Surfel also the plain mean of its contacts' normals (its gate's reference).
  double normal_median = 0, normal_p90 = 0;
  double plain_median = 0, plain_p90 = 0;
  double ns_per_contact = 0.0;
  std::vector<double> errors;  // signed distance of every point [m], by id (`keep_errors`)
};

template <class Policy, class Shape>
Row fuse(const Shape& shape, const std::vector<Contact<double>>& contacts, std::size_t count,
         const std::filesystem::path& ply, double radius, bool keep_errors = false,
         const typename Policy::Config& policy = {}) {
  tf::ContactCloud<Policy, index::VoxelHash<double>> cloud(
      {.association_radius = radius, .fusion = policy});
  cloud.reserve(count);
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < count; ++i) (void)cloud.insert(contacts[i]);
  Row r;
  r.ns_per_contact = 1e9 *
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() /
                     static_cast<double>(count);
  const PointCloud<double> pc = cloud.to_point_cloud();
  r.m = sim::reconstruction_metrics(shape, pc.points, count, {.coverage_samples = 5000});
  std::vector<Vec3d> confirmed, sparse, mid, many;
  for (std::size_t i = 0; i < pc.size(); ++i) {
    const double seen = pc.field("observations")->values[i];
    (seen >= 5 ? confirmed : sparse).push_back(pc.points[i]);
    if (seen >= 20) (seen >= 100 ? many : mid).push_back(pc.points[i]);
  }
  r.confirmed = sim::surface_error(shape, confirmed);
  r.sparse = sim::surface_error(shape, sparse);
  r.sparse_points = sparse.size();
  r.mid = sim::surface_error(shape, mid);
  r.mid_points = mid.size();
  r.many = sim::surface_error(shape, many);
  r.many_points = many.size();
  // Confident points: at least 3 contacts, and across the surface as certain as one fingertip
  // contact (0.3 mm); a point only the palm pad (1.5 mm) has seen does not count yet.
  r.supported = sim::surface_error(
      shape, cloud.to_point_cloud({3, std::numeric_limits<double>::infinity(), 0.3e-3}).points);
  r.confirmed_points = confirmed.size();
  if (!pc.normals.empty()) {
    std::vector<double> angles, plain;
    for (std::size_t i = 0; i < pc.size(); ++i) {
      if (pc.field("observations")->values[i] < 5) continue;
      const Vec3d truth = shape.normal(pc.points[i]);
      angles.push_back(std::acos(std::clamp(truth.dot(pc.normals[i]), -1.0, 1.0)));
      if constexpr (std::is_same_v<Policy, tf::Surfel<double>>) {
        // (to_point_cloud keeps the points in id order.)
        const Vec3d& mean = cloud.state(static_cast<index::PointId>(i)).unit_normal;
        plain.push_back(std::acos(std::clamp(truth.dot(mean), -1.0, 1.0)));
      }
    }
    const auto median_p90 = [](std::vector<double>& v, double& median, double& p90) {
      if (v.empty()) return;
      std::sort(v.begin(), v.end());
      median = v[v.size() / 2];
      p90 = v[(v.size() * 9) / 10];
    };
    median_p90(angles, r.normal_median, r.normal_p90);
    median_p90(plain, r.plain_median, r.plain_p90);
  }
  if (keep_errors) {
    for (const Vec3d& x : pc.points) r.errors.push_back(shape.signed_distance(x));
  }
  if (!ply.empty()) io::write_ply(ply.string(), pc);
  return r;
}

std::string safe(std::string s) {
  std::string out;
  for (const char c : s) {
    const bool word = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    if (word) {
      out.push_back(c);
    } else if (!out.empty() && out.back() != '_') {
      out.push_back('_');
    }
  }
  while (!out.empty() && out.back() == '_') out.pop_back();
  return out;
}

struct Study {
  std::vector<double> contacts;                      // checkpoints
  std::vector<double> raw, average, kalman, surfel;  // RMS error [mm] at each checkpoint
  std::vector<double> average3, kalman3, surfel3;    // the same over the confident points
  // Surfel's signed error of every point [m] at each checkpoint, by point id. A cloud only
  // appends points and the stream's prefixes are fused alike, so the points of one checkpoint
  // are the first ones of the next.
  std::vector<std::vector<double>> surfel_errors;
};

// The largest rise of a series over its lowest earlier value (0 when it never rises).
double largest_rise(const std::vector<double>& v) {
  double rise = 0, lowest = v.empty() ? 0.0 : v[0];
  for (const double x : v) {
    rise = std::max(rise, x / lowest - 1.0);
    lowest = std::min(lowest, x);
  }
  return rise;
}

// RMS [mm] of the first `m` of a cloud's signed errors [m].
double rms_of_first(const std::vector<double>& e, std::size_t m) {
  double sum = 0;
  for (std::size_t i = 0; i < m; ++i) sum += e[i] * e[i];
  return m > 0 ? 1e3 * std::sqrt(sum / double(m)) : 0.0;
}

// The largest rise, from one checkpoint to the next, of the RMS over the points the earlier
// one had (a cloud only appends points, so they are its first ones in the later cloud), over
// the checkpoints that had at least `min_points` points.
double largest_rise_of_kept_points(const std::vector<std::vector<double>>& errors,
                                   std::size_t min_points = 0) {
  double rise = 0;
  for (std::size_t k = 1; k < errors.size(); ++k) {
    const std::size_t m = errors[k - 1].size();
    if (m == 0 || m < min_points) continue;
    rise = std::max(rise, rms_of_first(errors[k], m) / rms_of_first(errors[k - 1], m) - 1.0);
  }
  return rise;
}

// The stream of a study: several slides from random starts, so the cloud covers much of the
// object. With two pads (`mixed`), the fingertip and the palm pad explore at the same time:
// each makes its own slides, and their streams are interleaved in blocks of 200 contacts, so
// that every prefix of the stream (the error curve's checkpoints) holds both in equal parts.
template <class Shape>
std::vector<Contact<double>> study_stream(const Shape& shape, std::size_t n,
                                          const sim::SlidingConfig& noise, bool mixed) {
  const auto slides = [&](std::size_t count, bool palm, std::uint64_t salt) {
    std::vector<Contact<double>> part;
    for (std::uint64_t s = 0; part.size() < count; ++s) {
      sim::SlidingConfig c = noise;
      c.seed = noise.seed * 101 + 2 * s + salt;
      if (palm) {
        c.pitch = 5e-3;
        c.sigma_normal = 1.5e-3;
      }
      const auto more = sim::sliding_exploration(
          shape, std::min<std::size_t>(count - part.size(), count / 4 + 1), c);
      part.insert(part.end(), more.begin(), more.end());
    }
    return part;
  };
  if (!mixed) return slides(n, false, 0);
  std::vector<Contact<double>> contacts;
  const auto tip = slides(n / 2, false, 0);
  const auto palm = slides(n - n / 2, true, 1);
  constexpr std::size_t kBlock = 200;
  for (std::size_t b = 0; contacts.size() < n; b += kBlock) {
    for (const auto* stream : {&tip, &palm}) {
      const std::size_t end = std::min(b + kBlock, stream->size());
      if (b < end) contacts.insert(contacts.end(), stream->begin() + b, stream->begin() + end);
    }
  }
  return contacts;
}

const char* const kStudyHeader =
    "shape                      policy    points compact signed mm mean mm  rms mm  max mm  "
    "cover |   n>=5  rms mm\n";

// One shape's table rows: the four policies on the whole stream; their clouds go to `out`.
// `normals` gets the shape's row of Surfel's point normals.
template <class Shape>
std::string study(const char* name, const Shape& shape, std::size_t n,
                  const sim::SlidingConfig& noise, const std::filesystem::path& out, bool mixed,
                  double radius, std::string& normals) {
  const std::vector<Contact<double>> contacts = study_stream(shape, n, noise, mixed);
  std::string text;
  const auto line = [&](const char* policy, const Row& r) {
    appendf(text, "%-26s %-8s %7zu %6.1fx %+8.3f %7.3f %7.3f %7.2f %5.1f%% | %6zu %7.3f\n", name,
            policy, r.m.points, r.m.compaction, 1e3 * r.m.error.signed_mean, 1e3 * r.m.error.mean,
            1e3 * r.m.error.rms, 1e3 * r.m.error.max, 100.0 * r.m.coverage, r.confirmed_points,
            1e3 * r.confirmed.rms);
  };
  const std::string stem = out.empty() ? std::string() : (out / safe(name)).string();
  const auto file = [&](const char* policy) {
    return stem.empty() ? std::filesystem::path()
                        : std::filesystem::path(stem + "_" + policy + ".ply");
  };
  line("raw", fuse<tf::Raw<double>>(shape, contacts, n, file("raw"), radius));
  line("average", fuse<tf::Average<double>>(shape, contacts, n, file("average"), radius));
  line("kalman", fuse<tf::Kalman<double>>(shape, contacts, n, file("kalman"), radius));
  const Row sur = fuse<tf::Surfel<double>>(shape, contacts, n, file("surfel"), radius);
  line("surfel", sur);
  normals.clear();
  appendf(normals, "%-26s | %5.1f / %5.1f | %5.1f / %5.1f\n", name, 1e3 * sur.normal_median,
          1e3 * sur.normal_p90, 1e3 * sur.plain_median, 1e3 * sur.plain_p90);
  return text;
}

// One checkpoint of the error curve: every policy on the first `k` contacts of the stream.
template <class Shape>
void curve_point(const Shape& shape, const std::vector<Contact<double>>& contacts, std::size_t k,
                 double radius, Study& curve, std::size_t at) {
  curve.contacts[at] = static_cast<double>(k);
  curve.raw[at] = 1e3 * fuse<tf::Raw<double>>(shape, contacts, k, {}, radius).m.error.rms;
  const Row a = fuse<tf::Average<double>>(shape, contacts, k, {}, radius);
  const Row kf = fuse<tf::Kalman<double>>(shape, contacts, k, {}, radius);
  Row sf = fuse<tf::Surfel<double>>(shape, contacts, k, {}, radius, true);
  curve.surfel_errors[at] = std::move(sf.errors);
  curve.average[at] = 1e3 * a.m.error.rms;
  curve.kalman[at] = 1e3 * kf.m.error.rms;
  curve.surfel[at] = 1e3 * sf.m.error.rms;
  curve.average3[at] = 1e3 * a.supported.rms;
  curve.kalman3[at] = 1e3 * kf.supported.rms;
  curve.surfel3[at] = 1e3 * sf.supported.rms;
}

// Raw per-tactel contacts binned by the true depth of their tactel (the compression a noiseless
// reading would give): below 0.1, 0.2, 0.4, 0.8 mm and deeper. The censoring correction has a
// different bias at each depth, so the mean over a stream depends on how its frames spread the
// tactels over the depths; per band it does not.
struct DepthBands {
  static constexpr std::size_t kBands = 5;
  static constexpr double kUpper[kBands - 1] = {0.1e-3, 0.2e-3, 0.4e-3, 0.8e-3};
  double sum[kBands] = {}, count[kBands] = {};  // signed distances [m] and contacts per band

  // Adds the per-tactel contacts of `ex` (one per active tactel, in pad order and row-major
  // tactel order within a pad, as sensor::ContactExtractor gives them).
  template <class Exploration>
  void add(const Exploration& ex, const sim::SensorModel& model) {
    const sensor::PadGeometry& g = model.geometry;
    for (const auto& frame : ex.frames) {
      std::size_t k = 0;
      for (const auto& pad : frame.pads) {
        const Vec3d back = -pad.true_pose.linear().col(2);
        for (int r = 0; r < g.rows; ++r) {
          for (int c = 0; c < g.cols; ++c) {
            const int reading = pad.counts(r, c);
            if (reading < model.threshold || reading >= model.levels - 1) continue;
            if (k >= frame.contacts.size()) throw std::logic_error("DepthBands: fewer contacts");
            const double depth = sim::compression(ex.truth, pad.true_pose * g.tactel(r, c), back);
            std::size_t band = 0;
            while (band + 1 < kBands && depth >= kUpper[band]) ++band;
            sum[band] += ex.truth.signed_distance(frame.contacts[k++].position);
            count[band] += 1;
          }
        }
      }
      if (k != frame.contacts.size()) throw std::logic_error("DepthBands: more contacts");
    }
  }
};

// The tactile pad model (sensor/, sim/sensor.hpp, sim/exploration.hpp): a DSA-like 14x6 pad
// slides, a three-finger hand with two pads per finger grasps, and a fingertip pad palpates;
// the three streams in turn, with contacts per active tactel or one per pad and frame. Three
// seeds; the RMS and the signed (outside minus inside) error of each policy, and of the raw
// contacts.
struct PadLine {
  std::string text;
  bool surfel_ahead = false;
  bool surfel_ahead_supported = false;  // over the points of at least 5 contacts
  bool surfel_more_sparse = false;      // more points of under 5 contacts than averaging
  // Surfel against contacts (prefixes of 1/64, 1/32, .. of the stream, then all of it): the
  // largest rise of the RMS over every point, and over the points of the previous checkpoint.
  double rise_every = 0, rise_kept = 0;
  double rise_kept_20 = 0;  // the same from checkpoints of at least 20 points
  std::string name;
  int seed = 0;
  DepthBands bands;     // the raw contacts by true depth (per tactel only)
  std::string support;  // averaging and Surfel over the points of 20-99 and 100+ contacts
  double normal_median = 0, normal_p90 = 0;  // Surfel's point normals [rad] (Row)
};

template <class Shape>
PadLine pad_study(const char* name, const Shape& shape, bool quick, sim::ContactMode mode,
                  std::uint64_t seed) {
  constexpr double kGate = 4e-3;  // 4 sigma of the in-plane quantisation (0.98 mm)
  const int scale = quick ? 1 : 4;
  sim::ExplorationConfig cfg;
  cfg.contacts.mode = mode;
  cfg.seed = seed;
  std::vector<Contact<double>> contacts;
  PadLine out;
  const auto add = [&](const auto& ex) {
    const auto part = ex.contacts();
    contacts.insert(contacts.end(), part.begin(), part.end());
    if (mode == sim::ContactMode::per_tactel) out.bands.add(ex, cfg.sensor);
  };
  add(sim::explore_sliding(shape, cfg, {.slides = 2 * scale, .frames = 500}));
  add(sim::explore_grasps(shape, cfg, {.grasps = 4 * scale}));
  add(sim::explore_palpation(shape, cfg, {.touches = 20 * scale}));
  const Row raw = fuse<tf::Raw<double>>(shape, contacts, contacts.size(), {}, kGate);
  const Row avg = fuse<tf::Average<double>>(shape, contacts, contacts.size(), {}, kGate);
  const Row kal = fuse<tf::Kalman<double>>(shape, contacts, contacts.size(), {}, kGate);
  Row sur = fuse<tf::Surfel<double>>(shape, contacts, contacts.size(), {}, kGate, true);
  std::vector<double> every;
  std::vector<std::vector<double>> errors;
  for (int k = 6; k >= 1; --k) {
    Row r = fuse<tf::Surfel<double>>(shape, contacts, contacts.size() >> k, {}, kGate, true);
    every.push_back(r.m.error.rms);
    errors.push_back(std::move(r.errors));
  }
  every.push_back(sur.m.error.rms);
  errors.push_back(std::move(sur.errors));
  const auto cell = [](const Row& r) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%6.3f %+7.3f", 1e3 * r.m.error.rms,
                  1e3 * r.m.error.signed_mean);
    return std::string(buf);
  };
  out.surfel_ahead = sur.m.error.rms < avg.m.error.rms;
  out.surfel_ahead_supported = sur.confirmed.rms < avg.confirmed.rms;
  out.surfel_more_sparse = sur.sparse_points > avg.sparse_points;
  out.name = name;
  out.seed = int(seed);
  out.rise_every = largest_rise(every);
  out.rise_kept = largest_rise_of_kept_points(errors);
  out.rise_kept_20 = largest_rise_of_kept_points(errors, 20);
  out.normal_median = sur.normal_median;
  out.normal_p90 = sur.normal_p90;
  appendf(out.text,
          "%-26s %-10s %4d %8zu | %s | %s | %s | %s | %6.3f %6.3f | %3zu %6.3f %3zu %6.3f%s\n",
          name, mode == sim::ContactMode::per_tactel ? "per tactel" : "per pad", int(seed),
          contacts.size(), cell(raw).c_str(), cell(avg).c_str(), cell(kal).c_str(),
          cell(sur).c_str(), 1e3 * avg.confirmed.rms, 1e3 * sur.confirmed.rms, avg.sparse_points,
          1e3 * avg.sparse.rms, sur.sparse_points, 1e3 * sur.sparse.rms,
          out.surfel_ahead ? "" : "  (average ahead)");
  const auto band = [](const Row& r, bool many) {
    const sim::SurfaceError& e = many ? r.many : r.mid;
    char buf[48];
    std::snprintf(buf, sizeof buf, "%6.3f %+7.3f", 1e3 * e.rms, 1e3 * e.signed_mean);
    return std::string(buf);
  };
  appendf(out.support, "%-26s %4d | %3zu %s  %3zu %s | %3zu %s  %3zu %s\n", name, int(seed),
          avg.mid_points, band(avg, false).c_str(), sur.mid_points, band(sur, false).c_str(),
          avg.many_points, band(avg, true).c_str(), sur.many_points, band(sur, true).c_str());
  return out;
}

constexpr const char* kUsage =
    "usage: 02_fusion_study [--quick] [--out DIR] [--threads N]\n"
    "Raw vs Average vs Kalman vs Surfel fusion of simulated explorations of seven shapes: points,\n"
    "compaction, distance to the true surface, coverage; PLY clouds and an SVG plot of error\n"
    "against contacts. --threads N runs the shapes, seeds and checkpoints on N threads (default\n"
    "0: every core); the output is the same for any N.\n";

// Distance of a surface point to the nearest crease (an edge, a rim, an apex) [m]; infinite on
// smooth shapes.
double crease_distance(const sim::Box& box, const Vec3d& p) {
  const Vec3d d = box.half_extents - p.cwiseAbs();
  double a[3] = {d[0], d[1], d[2]};
  std::sort(a, a + 3);
  return std::max(a[1], 0.0);  // a[0] is the face's own axis
}
double crease_distance(const sim::Cylinder& c, const Vec3d& p) {
  const double r = std::hypot(p.x(), p.y());
  if (std::abs(r - c.radius) < 1e-9 * c.radius) return c.half_height - std::abs(p.z());
  return c.radius - r;
}
double crease_distance(const sim::Cone& c, const Vec3d& p) {
  const Eigen::Vector2d q(std::hypot(p.x(), p.y()), p.z());
  return std::min((q - Eigen::Vector2d(c.radius, -0.5 * c.height)).norm(),
                  (q - Eigen::Vector2d(0.0, 0.5 * c.height)).norm());
}
template <class Shape>
double crease_distance(const Shape&, const Vec3d&) {
  return std::numeric_limits<double>::infinity();
}

// One policy on one stream of the robustness matrix: over the points of 5 or more contacts,
// RMS and signed error [m], and the RMS of those within `kCreaseBand` of a crease.
struct MatrixFit {
  double rms = 0, signed_mean = 0, crease_rms = 0;
  std::size_t crease_points = 0;
};
constexpr double kCreaseBand = 4e-3;  // the association radius

template <class Policy, class Shape>
MatrixFit matrix_fit(const Shape& shape, const std::vector<Contact<double>>& contacts,
                     std::size_t count, const typename Policy::Config& policy = {}) {
  tf::ContactCloud<Policy, index::VoxelHash<double>> cloud(
      {.association_radius = 4e-3, .fusion = policy});
  cloud.reserve(count);
  for (std::size_t i = 0; i < count; ++i) (void)cloud.insert(contacts[i]);
  const auto points = cloud.to_point_cloud({5}).points;
  MatrixFit f;
  double s2 = 0, s = 0, c2 = 0;
  for (const Vec3d& x : points) {
    const double d = shape.signed_distance(x);
    s2 += d * d;
    s += d;
    if (crease_distance(shape, shape.closest_point(x)) < kCreaseBand) {
      c2 += d * d;
      ++f.crease_points;
    }
  }
  const double m = std::max<double>(1.0, double(points.size()));
  f.rms = std::sqrt(s2 / m);
  f.signed_mean = s / m;
  f.crease_rms = f.crease_points ? std::sqrt(c2 / double(f.crease_points)) : 0.0;
  return f;
}

// A cell of the robustness matrix: the stream's settings, changed one factor at a time from the
// default (first) and all adverse at once (last).
struct MatrixCell {
  const char* name;
  sim::ContactStreamConfig stream;
};

std::vector<MatrixCell> matrix_cells() {
  const sim::ContactStreamConfig d{};  // 1 mm lateral, 0.05 rad unstated, sharp, no footprint
  std::vector<MatrixCell> cells{{"default", d}};
  const auto with = [&](const char* name, auto change) {
    sim::ContactStreamConfig c = d;
    change(c);
    cells.push_back({name, c});
  };
  with("lateral 0", [](auto& c) { c.sigma_lateral = 0; });
  with("lateral 0.5 mm", [](auto& c) { c.sigma_lateral = 0.5e-3; });
  with("lateral 1.5 mm", [](auto& c) { c.sigma_lateral = 1.5e-3; });
  with("normals exact", [](auto& c) { c.normal_noise = 0; });
  with("normals 0.1 rad", [](auto& c) { c.normal_noise = 0.1; });
  with("normal_sigma stated", [](auto& c) { c.state_normal_sigma = true; });
  with("footprint 2x2", [](auto& c) { c.footprint = 2; });
  with("depth-map normals", [](auto& c) { c.normal_smoothing = 1.7e-3; });
  with("all adverse", [](auto& c) {
    c.sigma_lateral = 1.5e-3;
    c.normal_noise = 0.1;
    c.footprint = 2;
    c.normal_smoothing = 1.7e-3;
  });
  return cells;
}

// The robustness matrix (sim::contact_stream): every cell on seven shapes and `seeds` seeds,
// averaging, Kalman, Surfel, and Surfel told that the lateral covariance is a footprint (the
// contacts' footprint_sigma set to it: no lift removed). Prints a row per shape and seed,
// and per cell the worst ratios and signed errors.
void robustness_matrix(bool quick, unsigned threads) {
  const std::size_t n = quick ? 20000 : 200000, n_short = n / 10;
  const int seeds = quick ? 1 : 3;
  const std::vector<MatrixCell> cells = matrix_cells();
  const char* const shape_names[] = {"box",        "cylinder r30", "cone", "ellipsoid",
                                     "sphere r15", "sphere r40",   "torus"};
  constexpr std::size_t kShapes = 7;
  // Per job: average, kalman, surfel, surfel with the footprint; then both Surfels at n / 10.
  struct Job {
    MatrixFit fit[6];
  };
  std::vector<Job> results(cells.size() * kShapes * std::size_t(seeds));
  parallel_for(results.size(), threads, [&](std::size_t j) {
    const std::size_t cell = j / (kShapes * seeds), shape = j / seeds % kShapes;
    sim::ContactStreamConfig cfg = cells[cell].stream;
    cfg.contacts = n;
    cfg.seed = 1000 + j % seeds;
    const auto run = [&](const auto& sh) {
      const auto contacts = sim::contact_stream(sh, cfg);
      auto footprint = contacts;
      for (auto& c : footprint) c.footprint_sigma = cfg.sigma_lateral;
      Job& r = results[j];
      r.fit[0] = matrix_fit<tf::Average<double>>(sh, contacts, n);
      r.fit[1] = matrix_fit<tf::Kalman<double>>(sh, contacts, n);
      r.fit[2] = matrix_fit<tf::Surfel<double>>(sh, contacts, n);
      r.fit[3] = matrix_fit<tf::Surfel<double>>(sh, footprint, n);
      r.fit[4] = matrix_fit<tf::Surfel<double>>(sh, contacts, n_short);
      r.fit[5] = matrix_fit<tf::Surfel<double>>(sh, footprint, n_short);
    };
    switch (shape) {
      case 0:
        run(sim::Box());
        break;
      case 1:
        run(sim::Cylinder(0.03, 0.05));
        break;
      case 2:
        run(sim::Cone());
        break;
      case 3:
        run(sim::Ellipsoid());
        break;
      case 4:
        run(sim::Sphere(0.015));
        break;
      case 5:
        run(sim::Sphere(0.04));
        break;
      default:
        run(sim::Torus());
        break;
    }
  });
  std::printf(
      "\nRobustness matrix (sim::contact_stream, %zu contacts, 4 mm radius, points of 5+ "
      "contacts; a point of fewer is mostly a lone contact, the same for every policy). Default "
      "cell: 14x6 sites at 3.4 mm, 0.3 mm along the normal and 1.0 mm across it, stated; normals "
      "sharp, turned by 0.05 rad per axis, not stated; pose error 0.2 mm and 0.02 rad per frame, "
      "not stated. Each other cell changes one factor, the last all adverse at once.\n"
      "RMS / signed error [mm], RMS over averaging's in brackets; crease: RMS of the points "
      "within 4 mm of an edge, rim or apex; footprint: Surfel with the contacts' lateral sigma "
      "stated as their footprint_sigma (no lift removed).\n",
      n);
  const bool smooth[kShapes] = {false, false, false, true, true, true, true};
  // Per policy (average, kalman, surfel), the worst over every run of the larger of its RMS over
  // averaging's and over 1.05 times Kalman's: how far it misses the acceptance bound, 1 meeting it.
  double worst_case[3] = {0, 0, 0};
  const char* worst_where[3] = {"", "", ""};
  for (std::size_t cell = 0; cell < cells.size(); ++cell) {
    std::printf(
        "\n[%s]\nshape          seed  average          kalman                  surfel             "
        "     surfel, footprint      | crease: kalman surfel footprint\n",
        cells[cell].name);
    double worst_avg[2] = {0, 0}, worst_kal[2] = {0, 0}, worst_signed[2] = {0, 0},
           worst_rise[2] = {-1, -1};
    for (std::size_t shape = 0; shape < kShapes; ++shape) {
      for (int seed = 0; seed < seeds; ++seed) {
        const Job& r = results[(cell * kShapes + shape) * std::size_t(seeds) + std::size_t(seed)];
        const double ra = r.fit[0].rms;
        std::printf("%-14s %4d  %.3f / %+.3f", shape_names[shape], seed, 1e3 * ra,
                    1e3 * r.fit[0].signed_mean);
        for (int p = 1; p < 4; ++p) {
          std::printf("   %.3f / %+.3f (%.2f)", 1e3 * r.fit[p].rms, 1e3 * r.fit[p].signed_mean,
                      r.fit[p].rms / ra);
        }
        if (r.fit[1].crease_points > 0) {
          std::printf(" | %.3f %.3f %.3f", 1e3 * r.fit[1].crease_rms, 1e3 * r.fit[2].crease_rms,
                      1e3 * r.fit[3].crease_rms);
        }
        std::printf("\n");
        for (int p = 0; p < 3; ++p) {
          const double w = std::max(r.fit[p].rms / ra, r.fit[p].rms / (1.05 * r.fit[1].rms));
          if (w > worst_case[p]) {
            worst_case[p] = w;
            worst_where[p] = cells[cell].name;
          }
        }
        for (int k = 0; k < 2; ++k) {
          const MatrixFit& f = r.fit[2 + k];
          worst_avg[k] = std::max(worst_avg[k], f.rms / ra);
          worst_kal[k] = std::max(worst_kal[k], f.rms / r.fit[1].rms);
          if (smooth[shape] && std::abs(f.signed_mean) > std::abs(worst_signed[k])) {
            worst_signed[k] = f.signed_mean;
          }
          worst_rise[k] = std::max(worst_rise[k], f.rms / r.fit[4 + k].rms - 1.0);
        }
      }
    }
    for (int k = 0; k < 2; ++k) {
      std::printf(
          "%s: worst RMS over averaging's %.2f, over Kalman's %.2f; largest signed error on "
          "smooth shapes %+.3f mm; RMS from %zu to %zu contacts: largest rise %+.0f %%\n",
          k == 0 ? "  surfel" : "  surfel, footprint", worst_avg[k], worst_kal[k],
          1e3 * worst_signed[k], n_short, n, 100.0 * worst_rise[k]);
    }
  }
  std::printf(
      "\nWorst case over every cell, shape and seed of max(RMS / averaging's, RMS / (1.05 "
      "Kalman's)):\n");
  const char* const policy_names[3] = {"average", "kalman", "surfel"};
  for (int p = 0; p < 3; ++p) {
    std::printf("  %-8s %.2f (%s)\n", policy_names[p], worst_case[p], worst_where[p]);
  }
}

// A real tactel reports the indentation averaged over its footprint, not at its centre
// (read_pad's footprint): the pad model with and without it, and with readings-to-contacts
// told so (ContactOptions::tactel_area), sliding on two spheres.
void footprint_table(bool quick) {
  std::printf(
      "\nThe pad model with footprint integration (a tactel reads its mean indentation, 2 x 2 "
      "Gauss points) against readings at the tactel centre, and with tactel_area; sliding, 4 x %d "
      "frames, 3.4 mm radius. Raw contacts' signed error, then RMS / signed error [mm]:\n"
      "shape       footprint  area seed  raw      average          kalman           surfel\n",
      quick ? 500 : 1500);
  for (const double R : {0.015, 0.04}) {
    for (const int variant : {0, 1, 2}) {
      for (const std::uint64_t seed : {11u, 12u}) {
        const sim::Sphere sphere(R);
        sim::ExplorationConfig cfg;
        cfg.footprint = variant == 0 ? 1 : 2;
        cfg.contacts.tactel_area = variant == 2;
        cfg.seed = seed;
        const auto contacts =
            sim::explore_sliding(sphere, cfg, {.slides = 4, .frames = quick ? 500u : 1500u})
                .contacts();
        double raw = 0.0;
        for (const auto& c : contacts) raw += sphere.signed_distance(c.position);
        raw /= double(contacts.size());
        const std::size_t m = contacts.size();
        const Row a = fuse<tf::Average<double>>(sphere, contacts, m, {}, 3.4e-3);
        const Row k = fuse<tf::Kalman<double>>(sphere, contacts, m, {}, 3.4e-3);
        const Row s = fuse<tf::Surfel<double>>(sphere, contacts, m, {}, 3.4e-3);
        std::printf("sphere r%-3.0f %9d %5s %4d  %+.3f", 1e3 * R, cfg.footprint,
                    variant == 2 ? "yes" : "no", int(seed), 1e3 * raw);
        for (const Row* r : {&a, &k, &s}) {
          std::printf("   %.3f / %+.3f", 1e3 * r->m.error.rms, 1e3 * r->m.error.signed_mean);
        }
        std::printf("\n");
      }
    }
  }
}

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("02_fusion_study");
  unsigned threads = 0;
  const taxel_cli::StudyOptions opt =
      taxel_cli::parse_study_options("02_fusion_study", kUsage, "fusion-study", argc, argv,
                                     [&](std::string_view a, taxel_cli::Args& args) {
                                       if (a != "--threads") return false;
                                       threads = args.number<unsigned>(0, 4096);
                                       return true;
                                     });
  const bool quick = opt.quick;
  const std::filesystem::path out = opt.out;
  std::filesystem::create_directories(out);
  const std::size_t n = quick ? 16000 : 128000;

  // A mesh as users bring them: written to PLY and read back.
  const sim::TriangleMesh ico = sim::icosphere(0.035, 3);
  PointCloud<double> vertices;
  vertices.points = ico.vertices();
  io::write_ply((out / "mesh_model.ply").string(), vertices, io::PlyFormat::binary_little_endian,
                ico.triangles());
  const io::PlyData loaded = io::read_ply((out / "mesh_model.ply").string());
  const sim::TriangleMesh mesh(loaded.cloud.points, loaded.triangles);

  // Anisotropic pad noise from two pads on alternate slides: a fingertip pad (0.3 mm along its
  // normal, quantisation over a 3.4 mm tactel across it, 0.98 mm) and a palm pad (1.5 mm along
  // the normal, 5 mm tactels: 1.44 mm across), both with 0.15 rad of kinematic tilt. Where the
  // slides overlap, Kalman weighs each contact by its own covariance; averaging cannot. The
  // association radius is 6 mm; the palm pad's contacts get a 9 mm gate (ContactCloud's
  // association_sigmas, 6 sigma of their noise along the normal), so that a noise tail cannot
  // land beyond every point, start one off the surface and gather more tail contacts there.
  sim::SlidingConfig aniso;
  aniso.sigma_normal = 0.3e-3;
  aniso.sigma_tilt = 0.15;
  aniso.speed = 0.15;
  aniso.seed = 3;
  constexpr double kRadius = 6e-3;          // the gate: about 4 sigma of the coarsest noise
  sim::SlidingConfig iso;                   // the control: isotropic, constant noise (below)
  iso.sigma_normal = tactel_sigma(3.4e-3);  // equal to the in-plane quantisation sigma
  iso.sigma_tilt = 0.0;
  iso.sigma_position = 0.0;
  iso.speed = 0.15;
  iso.seed = 3;

  // Every table row and every checkpoint of the error curve is a job of its own, run on
  // `threads` threads; each writes only its own slot, and the slots are printed in order, so
  // the output does not depend on the thread count. The heaviest jobs go first.
  std::vector<std::function<void()>> jobs;
  // The error curve on three streams (seeds), each checkpoint of each a job.
  constexpr std::uint64_t kCurveSeeds[] = {3, 4, 5};
  constexpr std::size_t kCurves = std::size(kCurveSeeds);
  std::vector<Study> curves(kCurves);
  std::vector<std::vector<Contact<double>>> curve_streams(kCurves);  // sphere r40, both pads
  std::vector<std::size_t> checkpoints;
  for (std::size_t k = n / 64; k <= n; k *= 2) checkpoints.push_back(k);
  for (std::size_t c = 0; c < kCurves; ++c) {
    Study& curve = curves[c];
    for (auto* v : {&curve.contacts, &curve.raw, &curve.average, &curve.kalman, &curve.surfel,
                    &curve.average3, &curve.kalman3, &curve.surfel3}) {
      v->assign(checkpoints.size(), 0.0);
    }
    curve.surfel_errors.resize(checkpoints.size());
    sim::SlidingConfig noise = aniso;
    noise.seed = kCurveSeeds[c];
    curve_streams[c] = study_stream(sim::Sphere(0.04), n, noise, true);
  }
  for (std::size_t i = checkpoints.size(); i-- > 0;) {
    for (std::size_t c = 0; c < kCurves; ++c) {
      jobs.emplace_back([&, i, c] {
        curve_point(sim::Sphere(0.04), curve_streams[c], checkpoints[i], kRadius, curves[c], i);
      });
    }
  }
  std::vector<std::string> tables(8), normal_rows(8);
  const auto table = [&](std::size_t slot, const char* name, const auto& shape,
                         const sim::SlidingConfig& noise, bool mixed, bool write) {
    jobs.emplace_back([&, slot, name, shape, mixed, write] {
      tables[slot] = study(name, shape, n, noise, write ? out : std::filesystem::path(), mixed,
                           kRadius, normal_rows[slot]);
    });
  };
  table(0, "sphere r40", sim::Sphere(0.04), aniso, true, true);
  table(1, "cylinder r30 h100", sim::Cylinder(0.03, 0.05), aniso, true, true);
  table(2, "box 80x60x40", sim::Box(Vec3d(0.04, 0.03, 0.02)), aniso, true, true);
  table(3, "cone r30 h60", sim::Cone(0.03, 0.06), aniso, true, true);
  table(4, "mesh icosphere r35 (PLY)", mesh, aniso, true, true);
  table(5, "ellipsoid 100x70x50", sim::Ellipsoid(Vec3d(0.05, 0.035, 0.025)), aniso, true, true);
  table(6, "torus R40 r15", sim::Torus(0.04, 0.015), aniso, true, true);
  table(7, "sphere r40 isotropic", sim::Sphere(0.04), iso, false, false);
  std::vector<PadLine> pads;
  const auto pad = [&](const char* name, const auto& shape) {
    for (const auto mode : {sim::ContactMode::per_tactel, sim::ContactMode::per_pad}) {
      for (const std::uint64_t seed : {11, 12, 13}) {
        const std::size_t slot = pads.size();
        pads.emplace_back();
        jobs.emplace_back([&, slot, name, shape, mode, seed] {
          pads[slot] = pad_study(name, shape, quick, mode, seed);
        });
      }
    }
  };
  pad("sphere r40", sim::Sphere(0.04));
  pad("sphere r15", sim::Sphere(0.015));
  pad("cylinder r30 h100", sim::Cylinder(0.03, 0.05));
  pad("box 80x60x40", sim::Box(Vec3d(0.04, 0.03, 0.02)));
  pad("cone r30 h60", sim::Cone(0.03, 0.06));
  pad("mesh icosphere r35 (PLY)", mesh);
  pad("ellipsoid 100x70x50", sim::Ellipsoid(Vec3d(0.05, 0.035, 0.025)));
  pad("torus R40 r15", sim::Torus(0.04, 0.015));
  std::atomic<std::size_t> done{0};
  parallel_for(jobs.size(), threads, [&](std::size_t j) {
    jobs[j]();
    std::fprintf(stderr, "\r  %zu / %zu jobs ", done.fetch_add(1) + 1, jobs.size());
  });
  std::fputs("\r\033[K", stderr);

  std::printf(
      "Anisotropic pad noise: fingertip pad 0.3 mm along the normal / 0.98 mm across and palm "
      "pad 1.5 / 1.44 mm exploring at the same time, 0.15 rad tilt; %zu contacts per shape, "
      "association radius 6 mm\n",
      n);
  std::fputs(kStudyHeader, stdout);
  for (std::size_t t = 0; t < 7; ++t) std::fputs(tables[t].c_str(), stdout);
  std::printf(
      "The paper's claim: Kalman fusion is more accurate than averaging, and both are far "
      "more compact than the raw contacts.\n\n");

  // Control: isotropic, constant noise (sigma 1 mm in every direction, no tilt): every contact
  // has the same R, so the Kalman mean is the running mean.
  std::printf("Control: isotropic constant noise (sigma 0.98 mm in every direction, no tilt)\n");
  std::fputs(kStudyHeader, stdout);
  std::fputs(tables[7].c_str(), stdout);
  std::printf("Theory: with the same isotropic R for every contact, Kalman equals averaging.\n\n");

  std::printf(
      "Both pads and the isotropic control, Surfel's point normals: the angle to the true surface "
      "normal at the point, over the points of at least 5 contacts, median / 90th percentile in "
      "mrad; its fitted surface's normal (what it reports) and the plain mean of its contacts' "
      "normals\n");
  std::printf("%-26s | %-13s | %s\n", "shape", "fitted", "plain mean");
  for (const std::string& row : normal_rows) std::fputs(row.c_str(), stdout);
  std::printf(
      "Here every contact of a frame carries the pad's one normal, and the fit weighs a slope by "
      "its contact's information along the normal, about 18 times more for the fingertip's than "
      "for the palm's, although both pads' normals carry the same tilt.\n\n");

  std::printf(
      "Pad model: a 14x6 DSA-like pad at 3.4 mm (12-bit readings, 0.3 mm depth noise, 0.2 mm and "
      "0.02 rad pose noise) slides, grasps (3 fingers x 2 pads) and palpates; gate 4 mm; each cell "
      "RMS and signed (outside minus inside) error in mm\n");
  std::printf("%-26s %-10s %4s %8s | %-15s | %-15s | %-15s | %-16s | %s | %s\n", "shape",
              "contacts", "seed", "", "raw rms/signed", "average", "kalman", "surfel (default)",
              "n>=5: average surfel", "n<5: points, rms: average  surfel");
  // Rows by mode, then shape, then seed (the jobs are by shape, then mode, then seed).
  int surfel_wins = 0, surfel_wins_supported = 0, behind = 0, behind_more_sparse = 0;
  for (std::size_t mode = 0; mode < 2; ++mode) {
    for (std::size_t shape = 0; shape < pads.size() / 6; ++shape) {
      for (std::size_t seed = 0; seed < 3; ++seed) {
        const PadLine& l = pads[shape * 6 + mode * 3 + seed];
        std::fputs(l.text.c_str(), stdout);
        surfel_wins += l.surfel_ahead ? 1 : 0;
        surfel_wins_supported += l.surfel_ahead_supported ? 1 : 0;
        behind += l.surfel_ahead ? 0 : 1;
        behind_more_sparse += !l.surfel_ahead && l.surfel_more_sparse ? 1 : 0;
      }
    }
  }
  std::printf(
      "Surfel (the default) ahead of averaging in %d of %zu shape x mode x seed runs over every "
      "point, and in %d of %zu over the points of at least 5 contacts (per pad, most of the RMS "
      "over every point comes from the few points of one or two contacts, whose error is a raw "
      "contact's; where Surfel is behind over every point, it holds more such points than "
      "averaging in %d of %d runs). Averaging lands inside a curved surface by the chord sag, "
      "Kalman outside by nearly as much; Surfel removes the sag with the curvature it fits to the "
      "contacts' normals.\n\n",
      surfel_wins, pads.size(), surfel_wins_supported, pads.size(), behind_more_sparse, behind);
  std::printf(
      "Pad model per pad, by support: the points of 20-99 contacts and of 100 or more, for "
      "averaging and Surfel: points, RMS and signed error in mm\n");
  std::printf("%-26s %4s | %-38s | %s\n", "shape", "seed", "20-99: average        surfel",
              "100+: average         surfel");
  for (std::size_t shape = 0; shape < pads.size() / 6; ++shape) {
    for (std::size_t seed = 0; seed < 3; ++seed) {
      std::fputs(pads[shape * 6 + 3 + seed].support.c_str(), stdout);
    }
  }
  std::printf(
      "Where a point has 100 contacts or more, averaging's chord sag shows and Surfel, which "
      "removes it, is ahead; at 20-99 the sag is smaller and about cancels the per-pad contacts' "
      "own outward bias, and both are limited by the contacts' noise.\n\n");
  std::printf(
      "Pad model, Surfel's point normals (its fitted surface's normal at the point): the angle "
      "to the true surface normal there, over the points of at least 5 contacts, median / 90th "
      "percentile in mrad, seeds 11, 12, 13\n");
  std::printf("%-26s | %-33s | %s\n", "shape", "per tactel", "per pad");
  for (std::size_t shape = 0; shape < pads.size() / 6; ++shape) {
    std::printf("%-26s", pads[shape * 6].name.c_str());
    for (std::size_t mode = 0; mode < 2; ++mode) {
      std::printf(" |");
      for (std::size_t seed = 0; seed < 3; ++seed) {
        const PadLine& l = pads[shape * 6 + mode * 3 + seed];
        std::printf(" %4.0f /%4.0f", 1e3 * l.normal_median, 1e3 * l.normal_p90);
      }
    }
    std::printf("\n");
  }
  std::printf(
      "Per pad, most of the worst tenth are points built from light touches alone: one or two "
      "active tactels measure no slope, so every contact's normal is the pad's, stated as a "
      "guess (0.21 rad). At edges, points also gather contacts from the next face.\n\n");
  std::printf(
      "Raw contacts per tactel by the true depth of their tactel (the three seeds pooled): signed "
      "error in mm, and the share of the contacts in each band\n");
  std::printf("%-26s | %-15s | %-15s | %-15s | %-15s | %-15s | %s\n", "shape", "below 0.1 mm",
              "0.1-0.2 mm", "0.2-0.4 mm", "0.4-0.8 mm", "0.8 mm and more", "all");
  for (std::size_t shape = 0; shape < pads.size() / 6; ++shape) {
    DepthBands pooled;
    for (std::size_t seed = 0; seed < 3; ++seed) {
      const DepthBands& b = pads[shape * 6 + seed].bands;
      for (std::size_t i = 0; i < DepthBands::kBands; ++i) {
        pooled.sum[i] += b.sum[i];
        pooled.count[i] += b.count[i];
      }
    }
    double sum = 0, count = 0;
    for (std::size_t i = 0; i < DepthBands::kBands; ++i) {
      sum += pooled.sum[i];
      count += pooled.count[i];
    }
    std::printf("%-26s", pads[shape * 6].name.c_str());
    for (std::size_t i = 0; i < DepthBands::kBands; ++i) {
      const double c = pooled.count[i];
      std::printf(" | %+7.3f  %4.1f %%", c > 0 ? 1e3 * pooled.sum[i] / c : 0.0,
                  count > 0 ? 100 * c / count : 0.0);
    }
    std::printf(" | %+7.3f\n", count > 0 ? 1e3 * sum / count : 0.0);
  }
  std::printf(
      "A tactel barely touching survives the noise floor only when its noise is positive; the "
      "censoring correction, evaluated where a quadric fitted to the pad puts the surface, leaves "
      "such tactels outside, the deeper ones unbiased or slightly inside. A stream's mean follows "
      "how many of its tactels lie in the first band.\n\n");
  std::printf(
      "Pad model, Surfel against contacts (the stream's first 1/64, 1/32, .., 1/2, then all of "
      "it; slides, then grasps, then palpation): the largest rise of the RMS over every point "
      "over an earlier checkpoint, and of the RMS over the points of the previous checkpoint, "
      "then and now\n");
  for (std::size_t mode = 0; mode < 2; ++mode) {
    double worst_every = 0, worst_kept = 0, worst_kept_20 = 0;
    for (std::size_t shape = 0; shape < pads.size() / 6; ++shape) {
      std::printf("%-26s %-10s", pads[shape * 6 + mode * 3].name.c_str(),
                  mode == 0 ? "per tactel" : "per pad");
      for (std::size_t seed = 0; seed < 3; ++seed) {
        const PadLine& l = pads[shape * 6 + mode * 3 + seed];
        std::printf(" | seed %d: every point %+5.0f %%, kept points %+4.0f %%", l.seed,
                    100.0 * l.rise_every, 100.0 * l.rise_kept);
        worst_every = std::max(worst_every, l.rise_every);
        worst_kept = std::max(worst_kept, l.rise_kept);
        worst_kept_20 = std::max(worst_kept_20, l.rise_kept_20);
      }
      std::printf("\n");
    }
    std::printf(
        "%s: largest rise %+.0f %% over every point, %+.0f %% over kept points (%+.0f %% from "
        "the checkpoints of 20 points or more)\n",
        mode == 0 ? "per tactel" : "per pad", 100.0 * worst_every, 100.0 * worst_kept,
        100.0 * worst_kept_20);
  }
  std::printf(
      "The RMS over every point follows which regions the cloud has reached: grasps and light "
      "touches start points of few contacts. Over the points already there it rises most where "
      "later contacts reach them across an edge (the box's, the cone's, the cylinder's rims). "
      "The first checkpoints hold a few points at about 0.01 mm, where a change of microns "
      "reads as tens of percent; the figure in brackets leaves out the checkpoints of fewer "
      "than 20 points.\n\n");

  // The mean over the seeds of every series.
  Study curve = curves[0];
  for (auto member : {&Study::raw, &Study::average, &Study::kalman, &Study::surfel,
                      &Study::average3, &Study::kalman3, &Study::surfel3}) {
    for (std::size_t k = 0; k < checkpoints.size(); ++k) {
      double sum = 0;
      for (const Study& c : curves) sum += (c.*member)[k];
      (curve.*member)[k] = sum / double(kCurves);
    }
  }
  io::LinePlot plot;
  plot.title =
      "RMS distance to the surface against contacts (sphere r40, anisotropic noise, mean of 3 "
      "seeds)";
  plot.x_label = "contacts (thousands)";
  plot.y_label = "RMS error (mm)";
  plot.y_min = 0.0;
  plot.series = {{"raw", {}, curve.raw},
                 {"average", {}, curve.average},
                 {"kalman", {}, curve.kalman},
                 {"surfel", {}, curve.surfel},
                 {"surfel, confident points", {}, curve.surfel3}};
  for (auto& s : plot.series) {
    for (const double c : curve.contacts) s.x.push_back(c / 1000.0);
  }
  io::write_file((out / "error_vs_contacts.svg").string(), io::render_svg(plot));
  std::printf(
      "RMS error [mm] against contacts (sphere r40, both pads; mean of the streams of seeds 3, 4 "
      "and 5): every point | confident points, to_point_cloud({3, inf, 0.3e-3}): at least 3 "
      "contacts and a standard deviation across the surface of at most 0.3 mm (a point only the "
      "palm pad has touched passes after about 25 of its contacts; as the stream grows, such "
      "points join the confident ones with errors up to that 0.3 mm, while every point's own "
      "error shrinks)\n");
  std::printf("%-10s %9s | %9s %9s %9s | %9s %9s %9s\n", "contacts", "raw", "average", "kalman",
              "surfel", "average", "kalman", "surfel");
  for (std::size_t k = 0; k < curve.contacts.size(); ++k) {
    std::printf("%-10.0f %9.3f | %9.3f %9.3f %9.3f | %9.3f %9.3f %9.3f\n", curve.contacts[k],
                curve.raw[k], curve.average[k], curve.kalman[k], curve.surfel[k], curve.average3[k],
                curve.kalman3[k], curve.surfel3[k]);
  }
  // Each seed's Surfel series, every point and confident points, and the largest rise of each
  // over an earlier checkpoint.
  for (std::size_t c = 0; c < kCurves; ++c) {
    for (const auto& [name, series] : {std::pair{"every point", &Study::surfel},
                                       std::pair{"confident points", &Study::surfel3}}) {
      std::printf("seed %d, surfel, %-16s:", int(kCurveSeeds[c]), name);
      for (const double x : curves[c].*series) std::printf(" %.3f", x);
      std::printf("  (largest rise over an earlier checkpoint %+.0f %%)\n",
                  100.0 * largest_rise(curves[c].*series));
    }
  }
  std::printf(
      "mean of the seeds: largest rise %+.0f %% over every point, %+.0f %% over the "
      "confident points\n",
      100.0 * largest_rise(curve.surfel), 100.0 * largest_rise(curve.surfel3));
  // Whether more contacts make the existing points worse: at each checkpoint, the RMS over the
  // points the previous checkpoint had, then and now. (The RMS over every point also moves as
  // the cloud grows into new regions, whose first points have few contacts; the first
  // checkpoints hold 13-22 points, so their RMS alone varies by about 1 / sqrt(2 m), 15 %.)
  std::printf(
      "Surfel, the points of the previous checkpoint, RMS [mm] then > now (a filter's promise: "
      "more contacts do not make a point worse):\n");
  for (std::size_t c = 0; c < kCurves; ++c) {
    std::printf("seed %d:", int(kCurveSeeds[c]));
    const auto& errors = curves[c].surfel_errors;
    for (std::size_t k = 1; k < errors.size(); ++k) {
      const std::size_t m = errors[k - 1].size();
      std::printf("%s %zu pts %.3f > %.3f", k > 1 ? "," : "", m, rms_of_first(errors[k - 1], m),
                  rms_of_first(errors[k], m));
    }
    std::printf("  (largest rise %+.0f %%)\n", 100.0 * largest_rise_of_kept_points(errors));
  }
  robustness_matrix(quick, threads);
  footprint_table(quick);
  std::printf("wrote %s/*.ply and %s/error_vs_contacts.svg\n", out.c_str(), out.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "02_fusion_study: %s\n", e.what());
  return 1;
}
