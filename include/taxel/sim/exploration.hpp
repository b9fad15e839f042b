// SPDX-License-Identifier: MIT
// Explorations with the tactile pad model (sensor.hpp): a pad sliding over a shape, a multi-pad
// hand closing on it, and a fingertip palpating it. Each yields time-stamped frames of pad
// readings and contacts, with the ground-truth shape and pose. Seeded and deterministic.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/sensor.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// Settings shared by every exploration.
struct ExplorationConfig {
  SensorModel sensor;                 ///< the pads (all pads of a hand are alike)
  sensor::ContactOptions contacts{};  ///< how readings become contacts (per tactel or per pad)
  double frame_rate = 1000.0;         ///< frames per second [Hz], in (0, 1e6]
  double indentation = 1.0e-3;        ///< how far a pad presses into the object [m], in (0, 1]
  /// Where a simulated tactel senses (read_pad): 1 at its centre, n in [2, 4] the mean
  /// indentation over its area (n x n Gauss-Legendre points), as a real tactel does.
  int footprint = 1;
  Eigen::Isometry3d object_pose = Eigen::Isometry3d::Identity();  ///< shape frame -> world
  std::uint64_t seed = 1;                                         ///< equal seeds, equal output

  /// Throws std::invalid_argument naming the first parameter out of range.
  template <class = void>
  void validate() const {
    sensor.validate();
    contacts.validate();
    if (!(frame_rate > 0) || !(frame_rate <= 1e6))
      throw std::invalid_argument("ExplorationConfig: frame_rate must be in (0, 1e6] Hz");
    if (!(indentation > 0) || !(indentation <= 1.0)) {
      throw std::invalid_argument(
          "ExplorationConfig: indentation must be in (0, 1] m (a length in millimetres given as "
          "metres?)");
    }
    if (footprint < 1 || footprint > 4)
      throw std::invalid_argument("ExplorationConfig: footprint must be in [1, 4]");
    if (!object_pose.matrix().allFinite())
      throw std::invalid_argument("ExplorationConfig: object_pose must be finite");
  }
};

/// One frame: the readings of the pads in use and the contacts they gave (world frame).
struct ExplorationFrame {
  double time = 0.0;                      ///< [s]
  std::vector<PadReading> pads;           ///< one per pad in use this frame
  std::vector<Contact<double>> contacts;  ///< from all pads, in pad order
};

/// An exploration's output and its ground truth.
template <Shape Sh>
struct Exploration {
  Posed<Sh> truth;                       ///< the explored shape at its world pose
  std::vector<ExplorationFrame> frames;  ///< in time order

  /// Number of contacts over all frames.
  std::size_t contact_count() const {
    std::size_t n = 0;
    for (const auto& f : frames) n += f.contacts.size();
    return n;
  }
  /// All contacts in time order.
  std::vector<Contact<double>> contacts() const {
    std::vector<Contact<double>> out;
    out.reserve(contact_count());
    for (const auto& f : frames) out.insert(out.end(), f.contacts.begin(), f.contacts.end());
    return out;
  }
};

/// A sliding exploration: the pad pressed `indentation` into the surface with its face tangent
/// to it, its long side along a random-walk heading.
struct SlideParams {
  int slides = 4;               ///< slides from random starts, >= 1
  std::size_t frames = 1000;    ///< frames per slide, >= 1
  double speed = 0.05;          ///< [m/s], >= 0
  double heading_sigma = 0.05;  ///< random-walk step of the heading [rad/frame], >= 0
};

/// Grasps of a hand with `fingers` fingers evenly spread around a random grasp axis, each with
/// `pads_per_finger` pads along it `pad_spacing` apart. Each finger closes straight towards the
/// axis at `closing_speed` and stops `indentation` past its first touch (a compliant,
/// position-controlled hand); then the hand holds for `hold_frames` frames and lets go. Every
/// frame has one reading per pad, `pad` = finger * pads_per_finger + pad on the finger; a pad
/// whose path misses the object stays open and reads nothing.
struct GraspParams {
  int grasps = 8;               ///< grasps with random axes, >= 1
  int fingers = 3;              ///< >= 1 (an SDH-2 has 3)
  int pads_per_finger = 2;      ///< proximal and distal, >= 1
  double pad_spacing = 0.05;    ///< distance of the pads along a finger [m], >= 0
  double closing_speed = 0.05;  ///< [m/s], > 0
  int hold_frames = 50;         ///< in [0, 1e6]
};

/// Palpation: one pad pokes the surface at uniformly random points, its face tangent there,
/// pressing in at `press_speed` to `indentation`, holding `hold_frames` frames.
struct PalpationParams {
  int touches = 40;           ///< >= 1
  double press_speed = 0.02;  ///< [m/s], > 0
  int hold_frames = 10;       ///< in [0, 1e6]
};

namespace detail {

/// Pad pose with face normal `z` (looking into the object), long side (pad y) along `y`
/// (orthogonalised), at `origin`.
template <class = void>
inline Eigen::Isometry3d pad_pose(const Vec3d& z, const Vec3d& y_hint, const Vec3d& origin) {
  Vec3d y = y_hint - y_hint.dot(z) * z;
  y = y.norm() > 1e-9 ? Vec3d(y.normalized()) : z.unitOrthogonal();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = y.cross(z);
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = origin;
  return T;
}

template <class Rng>
Vec3d random_unit(Rng& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec3d d(g(rng), g(rng), g(rng));
  while (d.squaredNorm() < 1e-24) d = Vec3d(g(rng), g(rng), g(rng));
  return d.normalized();
}

/// The frames a pad takes to press `distance` [m] in at `speed` [m/s] and `frame_rate` [Hz],
/// rounded up; throws std::invalid_argument naming `what` (the speed's parameter) beyond a
/// million frames, which no exploration needs and which would run for hours (a speed of
/// 1e-300 m/s would not end).
inline int frames_to_press(double distance, double speed, double frame_rate, const char* what) {
  const double n = std::ceil(distance / (speed / frame_rate));
  if (!(n <= 1e6)) {
    char text[256];
    std::snprintf(text, sizeof text,
                  "%s: pressing %.3g m in at %.3g m/s and %.3g Hz takes more than a million "
                  "frames; raise the speed or lower ExplorationConfig::frame_rate",
                  what, distance, speed, frame_rate);
    throw std::invalid_argument(text);
  }
  return static_cast<int>(n);
}

/// Smallest signed distance of a pad's tactels to the shape (negative: some tactel is inside).
template <Shape Sh>
double deepest(const Sh& shape, const PadGeometry& g, const Eigen::Isometry3d& pose) {
  double d = std::numeric_limits<double>::infinity();
  for (int r = 0; r < g.rows; ++r)
    for (int c = 0; c < g.cols; ++c) d = std::min(d, shape.signed_distance(pose * g.tactel(r, c)));
  return d;
}

template <Shape Sh>
void add_frame(Exploration<Sh>& ex, sensor::ContactExtractor& extractor, double time,
               std::vector<PadReading>&& pads) {
  ExplorationFrame f;
  f.time = time;
  f.pads = std::move(pads);
  for (const auto& p : f.pads) extractor.extract(p.counts, p.believed_pose, time, f.contacts);
  ex.frames.push_back(std::move(f));
}

}  // namespace detail

/// Slides a pad over `shape` (placed at cfg.object_pose): `p.slides` slides of `p.frames`
/// frames from random starts. Throws std::invalid_argument for invalid parameters.
template <SampleableShape Sh>
Exploration<Sh> explore_sliding(const Sh& shape, const ExplorationConfig& cfg,
                                const SlideParams& p = {}) {
  cfg.validate();
  if (p.slides < 1 || p.frames < 1 || !(p.speed >= 0) || !std::isfinite(p.speed) ||
      !(p.heading_sigma >= 0) || !std::isfinite(p.heading_sigma)) {
    throw std::invalid_argument(
        "SlideParams: slides and frames must be >= 1, speed and heading_sigma finite and >= 0");
  }
  Exploration<Sh> ex{Posed<Sh>{shape, cfg.object_pose}, {}};
  const Posed<Sh>& world = ex.truth;
  sensor::ContactExtractor extractor(cfg.sensor, cfg.contacts);
  std::mt19937_64 rng(cfg.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double step = p.speed / cfg.frame_rate;
  ex.frames.reserve(static_cast<std::size_t>(p.slides) * p.frames);
  std::size_t tick = 0;
  for (int s = 0; s < p.slides; ++s) {
    Vec3d at, n;
    sample_point(world, rng, at, n);
    Vec3d heading = n.cross(detail::random_unit(rng));
    if (heading.norm() < 1e-9) heading = n.unitOrthogonal();
    heading.normalize();
    for (std::size_t f = 0; f < p.frames; ++f, ++tick) {
      const Eigen::Isometry3d pose = detail::pad_pose(-n, heading, at - cfg.indentation * n);
      std::vector<PadReading> pads;
      pads.push_back(read_pad(world, cfg.sensor, pose, rng, 0, cfg.footprint));
      detail::add_frame(ex, extractor, double(tick) / cfg.frame_rate, std::move(pads));
      heading = Eigen::AngleAxisd(p.heading_sigma * gauss(rng), n) * heading;
      at = world.closest_point(at + step * heading);
      const Vec3d n_new = world.normal(at);
      const Vec3d h = heading - heading.dot(n_new) * n_new;
      heading = h.norm() > 1e-9 ? Vec3d(h.normalized()) : n_new.unitOrthogonal();
      n = n_new;
    }
  }
  return ex;
}

/// Closes a multi-pad hand on `shape` (placed at cfg.object_pose) `p.grasps` times. Throws
/// std::invalid_argument for invalid parameters.
template <SampleableShape Sh>
Exploration<Sh> explore_grasps(const Sh& shape, const ExplorationConfig& cfg,
                               const GraspParams& p = {}) {
  cfg.validate();
  if (p.grasps < 1 || p.fingers < 1 || p.pads_per_finger < 1 || p.fingers > 64 ||
      p.pads_per_finger > 64 || !(p.pad_spacing >= 0) || !std::isfinite(p.pad_spacing) ||
      !(p.closing_speed > 0) || !std::isfinite(p.closing_speed) || p.hold_frames < 0 ||
      p.hold_frames > 1000000) {
    throw std::invalid_argument(
        "GraspParams: grasps >= 1, fingers and pads_per_finger in [1, 64], pad_spacing >= 0, "
        "closing_speed > 0 and hold_frames in [0, 1e6]");
  }
  Exploration<Sh> ex{Posed<Sh>{shape, cfg.object_pose}, {}};
  const Posed<Sh>& world = ex.truth;
  sensor::ContactExtractor extractor(cfg.sensor, cfg.contacts);
  // Centre and reach of the object, from surface samples.
  const PointCloud<double> samples = sample_surface(world, 2000, cfg.seed ^ 0x5eedULL);
  Vec3d centre = Vec3d::Zero();
  for (const auto& q : samples.points) centre += q;
  centre /= double(samples.size());
  double reach = 0.0;
  for (const auto& q : samples.points) reach = std::max(reach, (q - centre).norm());
  const PadGeometry& g = cfg.sensor.geometry;
  const double half_diag = 0.5 * g.pitch * std::hypot(g.rows, g.cols);
  const double start = 1.2 * reach + cfg.indentation + 2e-3;  // pads start clear of the object
  const double scan = std::min(0.5 * g.pitch, 0.25 * reach);  // finer than any pad feature
  const double step = p.closing_speed / cfg.frame_rate;
  const int closing =
      detail::frames_to_press(cfg.indentation, p.closing_speed, cfg.frame_rate, "GraspParams") + 2;

  std::mt19937_64 rng(cfg.seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::size_t tick = 0;
  for (int k = 0; k < p.grasps; ++k) {
    const Vec3d axis = detail::random_unit(rng);
    const Vec3d e1 = axis.unitOrthogonal();
    const Vec3d e2 = axis.cross(e1);
    const double phase = std::numbers::pi * uniform(rng);
    const double height = 0.3 * reach * uniform(rng);  // where along the axis the hand grips
    struct Pad {
      Vec3d origin, inward;
      double touch;  // closing distance at first touch
    };
    std::vector<Pad> pads;
    for (int f = 0; f < p.fingers; ++f) {
      const double phi = phase + 2.0 * std::numbers::pi * f / p.fingers;
      const Vec3d radial = std::cos(phi) * e1 + std::sin(phi) * e2;
      for (int j = 0; j < p.pads_per_finger; ++j) {
        const double h = height + (j - 0.5 * (p.pads_per_finger - 1)) * p.pad_spacing;
        Pad pad{centre + h * axis + (start + half_diag) * radial, -radial, -1.0};
        const auto at = [&](double s) {
          return detail::pad_pose(pad.inward, axis, pad.origin + s * pad.inward);
        };
        // March until a tactel enters the object, then bisect the touching distance.
        double lo = 0.0;
        for (double s = 0.0; s <= 2.0 * (start + half_diag); s += scan) {
          if (detail::deepest(world, g, at(s)) <= 0.0) {
            double hi = s;
            for (int it = 0; it < 50; ++it) {
              const double mid = 0.5 * (lo + hi);
              (detail::deepest(world, g, at(mid)) <= 0.0 ? hi : lo) = mid;
            }
            pad.touch = hi;
            break;
          }
          lo = s;
        }
        pads.push_back(pad);
      }
    }
    if (std::none_of(pads.begin(), pads.end(), [](const Pad& q) { return q.touch >= 0.0; }))
      continue;
    for (int f = 0; f < closing + p.hold_frames; ++f, ++tick) {
      const double s_rel = std::min(double(f - 2) * step, cfg.indentation);
      std::vector<PadReading> readings;
      for (std::size_t i = 0; i < pads.size(); ++i) {
        const Pad& pad = pads[i];
        const double s = pad.touch >= 0.0 ? pad.touch + s_rel : 0.0;  // a miss stays open
        const Eigen::Isometry3d pose =
            detail::pad_pose(pad.inward, axis, pad.origin + s * pad.inward);
        readings.push_back(
            read_pad(world, cfg.sensor, pose, rng, static_cast<int>(i), cfg.footprint));
      }
      detail::add_frame(ex, extractor, double(tick) / cfg.frame_rate, std::move(readings));
    }
  }
  return ex;
}

/// Palpates `shape` (placed at cfg.object_pose) `p.touches` times with one pad. Throws
/// std::invalid_argument for invalid parameters.
template <SampleableShape Sh>
Exploration<Sh> explore_palpation(const Sh& shape, const ExplorationConfig& cfg,
                                  const PalpationParams& p = {}) {
  cfg.validate();
  if (p.touches < 1 || !(p.press_speed > 0) || !std::isfinite(p.press_speed) || p.hold_frames < 0 ||
      p.hold_frames > 1000000) {
    throw std::invalid_argument(
        "PalpationParams: touches >= 1, press_speed > 0 and hold_frames in [0, 1e6]");
  }
  Exploration<Sh> ex{Posed<Sh>{shape, cfg.object_pose}, {}};
  const Posed<Sh>& world = ex.truth;
  sensor::ContactExtractor extractor(cfg.sensor, cfg.contacts);
  std::mt19937_64 rng(cfg.seed);
  const double step = p.press_speed / cfg.frame_rate;
  const int pressing =
      detail::frames_to_press(cfg.indentation, p.press_speed, cfg.frame_rate, "PalpationParams") +
      2;
  std::size_t tick = 0;
  for (int k = 0; k < p.touches; ++k) {
    Vec3d at, n;
    sample_point(world, rng, at, n);
    const Vec3d y = detail::random_unit(rng);
    for (int f = 0; f < pressing + p.hold_frames; ++f, ++tick) {
      const double s = std::min(double(f - 2) * step, cfg.indentation);
      std::vector<PadReading> readings;
      readings.push_back(
          read_pad(world, cfg.sensor, detail::pad_pose(-n, y, at - s * n), rng, 0, cfg.footprint));
      detail::add_frame(ex, extractor, double(tick) / cfg.frame_rate, std::move(readings));
    }
  }
  return ex;
}

/// One poke along a ray, as a robot probing an object: the pad approaches `shape` (world frame;
/// wrap a placed shape in `Posed`) along origin + t direction (direction of any length > 0).
/// Where the ray first meets the surface (sphere tracing on the exact signed distance), the
/// pad, its face tangent there (a compliant wrist), presses in to cfg.indentation at
/// `p.press_speed` and holds `p.hold_frames` frames; `p.touches` is not used. Appends the
/// contacts of every frame to `out` (time from `start_time` at cfg.frame_rate) and returns the
/// point where the ray met the surface, or nothing when it misses within `max_distance`.
/// Throws std::invalid_argument for invalid parameters or a non-finite ray.
template <Shape Sh, class Rng>
std::optional<Vec3d> poke(const Sh& shape, const ExplorationConfig& cfg, const Vec3d& origin,
                          const Vec3d& direction, double max_distance, Rng& rng,
                          std::vector<Contact<double>>& out, const PalpationParams& p = {},
                          double start_time = 0.0) {
  cfg.validate();
  if (!origin.allFinite() || !direction.allFinite() || !(direction.norm() > 0.0) ||
      !(max_distance >= 0.0) || !std::isfinite(max_distance)) {
    throw std::invalid_argument("poke: the ray must be finite with a direction of length > 0");
  }
  if (!(p.press_speed > 0) || !std::isfinite(p.press_speed) || p.hold_frames < 0 ||
      p.hold_frames > 1000000) {
    throw std::invalid_argument("PalpationParams: press_speed > 0 and hold_frames in [0, 1e6]");
  }
  const Vec3d d = direction.normalized();
  double t = 0.0;
  std::optional<Vec3d> hit;
  for (int it = 0; it < 10000 && t <= max_distance; ++it) {
    const double s = shape.signed_distance(Vec3d(origin + t * d));
    if (s < 1e-9) {
      hit = origin + t * d;
      break;
    }
    t += s;
  }
  if (!hit) return std::nullopt;
  const Vec3d n = shape.normal(*hit);
  const Vec3d y = detail::random_unit(rng);
  sensor::ContactExtractor extractor(cfg.sensor, cfg.contacts);
  const double step = p.press_speed / cfg.frame_rate;
  const int pressing =
      detail::frames_to_press(cfg.indentation, p.press_speed, cfg.frame_rate, "PalpationParams") +
      2;
  for (int f = 0; f < pressing + p.hold_frames; ++f) {
    const double s = std::min(double(f - 2) * step, cfg.indentation);
    const PadReading r =
        read_pad(shape, cfg.sensor, detail::pad_pose(-n, y, *hit - s * n), rng, 0, cfg.footprint);
    extractor.extract(r.counts, r.believed_pose, start_time + double(f) / cfg.frame_rate, out);
  }
  return hit;
}

}  // namespace taxel::sim
