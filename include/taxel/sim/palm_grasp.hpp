// SPDX-License-Identifier: MIT
// Synthetic 32x32 palm-grasp pressure images for the second paper's four object classes
// (planar, one-edged, two-edged, cylindrical): a palm and finger strips with gaps pressing on
// the object, per-subject hand variation, sensor response, noise and 8-bit quantisation.
// Seeded and deterministic: an image depends only on (seed, subject, class, hand, grasp).
//
// The model (units: tactels; "across" is the direction across the fingers, "along" the
// direction of the fingers):
//  - Hand: a palm block (width = finger span + 2, `palm_length` long) and `fingers` strips of
//    width `finger_width` separated by `finger_gap` columns of no contact, finger lengths 80-100 %
//    of `finger_length` (middle fingers longest). Per subject: scale ~ N(1, scale_sd), finger
//    width and gap jitter, grip force ~ U(force_min, force_max), a personal pressure pattern
//    (palm heel vs finger pads). Per grasp: offset ~ N(0, offset_sd), rotation ~
//    N(0, rotation_sd), force varies +-10 %; the left hand is the mirror image of the right.
//    Soft tissue: the pressure of the palm and of each finger falls to 0 at the outline like a
//    Hertzian contact, sqrt(d / rim) within `rim` tactels of the edge.
//  - Object field p(w) over the signed distance w across the object's axis, which lies across
//    the palm, 0.45 palm lengths below the finger roots, at a random angle (+- object_angle_deg)
//    and offset (+- object_offset):
//      planar       p = 1 with a gentle random tilt (+-15 % over the hand);
//      one-edged    the hand rests on a face ending at an edge: p = plateau on one side, an
//                   edge ridge of height 1 and width sigma_e ~ U(edge_sigma) at the edge, falling
//                   to `overhang` beyond it;
//      two-edged    a cuboid of width ~ U(cuboid_width): plateau between two edge ridges,
//                   `overhang` outside;
//      cylindrical  p = sqrt(1 - (w/R)^2) inside radius R ~ U(cylinder_radius), `overhang`
//                   outside (fingers wrapping round) - smooth, no ridge.
//  - Sensor: value = gain * force * p * hand pattern * (1 + N(0, mult_noise)) + N(0, add_noise),
//    2x2 supersampled hand mask, clipped to [0, 255] and rounded; dead tactels read 0.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "taxel/image/types.hpp"

namespace taxel::sim {

/// The second paper's object classes; the value is the label used in data sets (1-based).
enum class GraspClass { planar = 1, one_edged = 2, two_edged = 3, cylindrical = 4 };

/// The four classes in label order.
inline constexpr std::array<GraspClass, 4> kGraspClasses{
    GraspClass::planar, GraspClass::one_edged, GraspClass::two_edged, GraspClass::cylindrical};

/// Lower-case class name ("planar", "one-edged", "two-edged", "cylindrical").
constexpr std::string_view to_string(GraspClass c) noexcept {
  switch (c) {
    case GraspClass::planar:
      return "planar";
    case GraspClass::one_edged:
      return "one-edged";
    case GraspClass::two_edged:
      return "two-edged";
    case GraspClass::cylindrical:
      return "cylindrical";
  }
  return "unknown";
}

/// A closed interval for uniform draws.
struct Range {
  double lo = 0.0;  ///< Smallest value.
  double hi = 0.0;  ///< Largest value.
};

/// Parameters of the palm-grasp model (see the file comment).
struct PalmGraspConfig {
  int rows = 32;  ///< Image height [tactels].
  int cols = 32;  ///< Image width [tactels].
  // Hand.
  int fingers = 4;              ///< Finger strips.
  double finger_width = 4.5;    ///< [tactels]
  double finger_gap = 1.3;      ///< Gap between fingers [tactels].
  double finger_length = 13.0;  ///< [tactels]
  double palm_length = 13.0;    ///< [tactels]
  double scale_sd = 0.08;       ///< Relative standard deviation of the hand size between subjects.
  double rim = 1.5;             ///< soft-tissue rim: pressure tapers to 0 over this many tactels
  // Placement.
  double offset_sd = 1.5;          ///< tactels
  double rotation_sd_deg = 7.0;    ///< hand rotation per grasp
  double object_angle_deg = 15.0;  ///< Largest angle of the object's axis to the palm's.
  double object_offset = 3.0;      ///< object axis offset, +- tactels
  // Force.
  /// Grip force, relative.
  Range force{0.55, 1.0};
  // Objects.
  double plateau = 0.45;       ///< pressure on a face next to an edge, relative to the ridge
  double overhang = 0.08;      ///< pressure beyond an edge or a cylinder
  Range edge_sigma{1.3, 2.6};  ///< width of an edge ridge
  /// Width of a two-edged object [tactels].
  Range cuboid_width{7.0, 16.0};
  /// [tactels]
  Range cylinder_radius{6.0, 15.0};
  // Sensor.
  double gain = 230.0;              ///< Reading of a full pressure, before noise.
  double mult_noise = 0.06;         ///< Relative sensor noise.
  double add_noise = 3.0;           ///< Additive sensor noise [reading units].
  double dead_tactel_prob = 0.003;  ///< Probability that a tactel reads 0.
};

/// One hand: the per-subject draw.
struct Subject {
  int id = 0;                             ///< Subject number.
  double scale = 1.0;                     ///< Hand size, relative.
  double finger_width = 4.5;              ///< [tactels]
  double finger_gap = 1.3;                ///< Gap between fingers [tactels].
  double force = 0.8;                     ///< Grip force, relative.
  double heel = 1.0;                      ///< palm-heel pressure factor
  double pads = 1.0;                      ///< finger-pad pressure factor
  std::array<double, 5> finger_length{};  ///< relative lengths
};

/// One synthetic image with its labels.
struct PalmGraspSample {
  image::ImageD image;                    ///< rows x cols pressure readings.
  GraspClass label = GraspClass::planar;  ///< The object class.
  int subject = 0;                        ///< The subject's number.
  bool right_hand = true;                 ///< False for a mirrored left hand.
  int grasp = 0;                          ///< The grasp's number within its subject and hand.
};

/// The synthesiser. Throws std::invalid_argument for an impossible configuration.
class PalmGraspSynth {
 public:
  /// Draws with `cfg`; equal seeds give equal images.
  explicit PalmGraspSynth(PalmGraspConfig cfg = {}, std::uint64_t seed = 1)
      : cfg_(cfg), seed_(seed) {
    if (cfg.rows < 8 || cfg.cols < 8 || cfg.rows > 1024 || cfg.cols > 1024) {
      throw std::invalid_argument("PalmGraspConfig: rows and cols must lie in [8, 1024]");
    }
    if (cfg.fingers < 1 || cfg.fingers > 5) {
      throw std::invalid_argument("PalmGraspConfig: fingers = " + std::to_string(cfg.fingers) +
                                  " is outside the allowed range [1, 5]");
    }
    if (!(cfg.finger_width > 0) || !(cfg.finger_gap >= 0) || !(cfg.gain > 0) ||
        !(cfg.force.lo > 0 && cfg.force.lo <= cfg.force.hi) ||
        !(cfg.edge_sigma.lo > 0 && cfg.edge_sigma.lo <= cfg.edge_sigma.hi) ||
        !(cfg.cylinder_radius.lo > 0 && cfg.cylinder_radius.lo <= cfg.cylinder_radius.hi) ||
        !(cfg.cuboid_width.lo > 0 && cfg.cuboid_width.lo <= cfg.cuboid_width.hi)) {
      throw std::invalid_argument(
          "PalmGraspConfig: widths, gain, force and object ranges must be "
          "positive with lo <= hi");
    }
  }

  /// Subject `id`'s hand (the same for every call).
  [[nodiscard]] Subject subject(int id) const {
    std::mt19937_64 rng(mix(seed_, static_cast<std::uint64_t>(id), 0x5b, 0));
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Subject s;
    s.id = id;
    s.scale = std::clamp(1.0 + cfg_.scale_sd * g(rng), 0.75, 1.25);
    s.finger_width = cfg_.finger_width * (1.0 + 0.08 * g(rng));
    s.finger_gap = std::max(0.6, cfg_.finger_gap * (1.0 + 0.25 * g(rng)));
    s.force = cfg_.force.lo + (cfg_.force.hi - cfg_.force.lo) * u(rng);
    s.heel = 0.85 + 0.3 * u(rng);
    s.pads = 0.85 + 0.3 * u(rng);
    static constexpr std::array<double, 5> kBase{0.82, 0.97, 1.0, 0.9, 0.75};
    for (std::size_t f = 0; f < 5; ++f) s.finger_length[f] = kBase[f] * (1.0 + 0.05 * g(rng));
    return s;
  }

  /// One grasp image.
  template <class = void>
  [[nodiscard]] image::ImageD render(const Subject& s, GraspClass cls, bool right_hand,
                                     int grasp) const {
    std::mt19937_64 rng(mix(seed_, static_cast<std::uint64_t>(s.id),
                            static_cast<std::uint64_t>(cls),
                            static_cast<std::uint64_t>(grasp) * 2 + (right_hand ? 1 : 0)));
    std::normal_distribution<double> g(0.0, 1.0);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const auto uni = [&](Range r) { return r.lo + (r.hi - r.lo) * u(rng); };

    const double force = s.force * (1.0 + 0.1 * (2.0 * u(rng) - 1.0));
    const double dx = cfg_.offset_sd * g(rng);
    const double dy = cfg_.offset_sd * g(rng);
    const double rot = cfg_.rotation_sd_deg * g(rng) * std::numbers::pi / 180.0;
    // Object axis: across the palm (along the hand's "across" direction), tilted and shifted.
    const double obj_angle =
        cfg_.object_angle_deg * (2.0 * u(rng) - 1.0) * std::numbers::pi / 180.0;
    const double obj_offset = cfg_.object_offset * (2.0 * u(rng) - 1.0);
    const double tilt_a = 0.15 * (2.0 * u(rng) - 1.0) / 12.0;
    const double tilt_b = 0.15 * (2.0 * u(rng) - 1.0) / 12.0;
    const double sigma = uni(cfg_.edge_sigma);
    const double half_width = 0.5 * uni(cfg_.cuboid_width);
    const double radius = uni(cfg_.cylinder_radius);
    const bool edge_side = u(rng) < 0.5;  // which side of a single edge the face is on

    const double span = cfg_.fingers * s.finger_width + (cfg_.fingers - 1) * s.finger_gap;
    const double palm_half = 0.5 * span + 1.0;
    const double rows = cfg_.rows;
    const double cols = cfg_.cols;
    // Hand frame origin: the finger/palm boundary, placed so that fingers point up the image.
    const double cy = 0.45 * rows + dy;
    const double cx = 0.5 * cols + dx;
    const double c = std::cos(rot);
    const double sn = std::sin(rot);
    const double oc = std::cos(obj_angle);
    const double os = std::sin(obj_angle);

    const auto object = [&](double w) {
      switch (cls) {
        case GraspClass::planar:
          return 1.0;
        case GraspClass::one_edged: {
          const double e = edge_side ? w - obj_offset : obj_offset - w;
          const double ridge = std::exp(-0.5 * (e / sigma) * (e / sigma));
          const double face = e < 0 ? cfg_.plateau : cfg_.overhang;
          return std::max(face, ridge);
        }
        case GraspClass::two_edged: {
          const double e = std::fabs(w - obj_offset) - half_width;
          const double ridge = std::exp(-0.5 * (e / sigma) * (e / sigma));
          return std::max(e < 0 ? cfg_.plateau : cfg_.overhang, ridge);
        }
        case GraspClass::cylindrical: {
          const double q = (w - obj_offset) / radius;
          return std::max(cfg_.overhang, q * q < 1.0 ? std::sqrt(1.0 - q * q) : 0.0);
        }
      }
      return 0.0;
    };

    image::ImageD img(cfg_.rows, cfg_.cols);
    for (int r = 0; r < cfg_.rows; ++r) {
      for (int col = 0; col < cfg_.cols; ++col) {
        double acc = 0.0;
        for (int sub = 0; sub < 4; ++sub) {  // 2x2 supersampling of the hand outline
          const double py = r + 0.25 + 0.5 * (sub / 2) - cy;
          const double px = col + 0.25 + 0.5 * (sub % 2) - cx;
          // Image -> hand frame (across a, along b; b < 0 towards the fingertips).
          double a = (c * px + sn * py) / s.scale;
          const double b = (-sn * px + c * py) / s.scale;
          if (!right_hand) a = -a;
          const double hand = hand_pressure(s, a, b, span, palm_half);
          if (hand <= 0.0) continue;
          // Object coordinate: distance across the object's axis, which runs along "across".
          const double w = -os * a + oc * (b - 0.45 * cfg_.palm_length);
          acc += hand * object(w) * (1.0 + tilt_a * a + tilt_b * b);
        }
        double v = 0.0;
        if (acc > 0.0) {
          v = cfg_.gain * force * 0.25 * acc * (1.0 + cfg_.mult_noise * g(rng));
        }
        v += cfg_.add_noise * g(rng);
        if (u(rng) < cfg_.dead_tactel_prob) v = 0.0;
        img(r, col) = std::round(std::clamp(v, 0.0, 255.0));
      }
    }
    return img;
  }

  /// A data set of `subjects` x 4 classes x `grasps` x 2 hands, ordered subject, class, grasp,
  /// hand (right first).
  template <class = void>
  [[nodiscard]] std::vector<PalmGraspSample> dataset(int subjects, int grasps) const {
    std::vector<PalmGraspSample> out;
    out.reserve(static_cast<std::size_t>(std::max(0, subjects * grasps * 8)));
    for (int sid = 0; sid < subjects; ++sid) {
      const Subject s = subject(sid);
      for (GraspClass cls : kGraspClasses) {
        for (int k = 0; k < grasps; ++k) {
          for (bool right : {true, false}) {
            out.push_back(PalmGraspSample{render(s, cls, right, k), cls, sid, right, k});
          }
        }
      }
    }
    return out;
  }

  /// The configuration.
  [[nodiscard]] const PalmGraspConfig& config() const noexcept { return cfg_; }
  /// The seed the images are drawn with.
  [[nodiscard]] std::uint64_t seed() const noexcept { return seed_; }

 private:
  // Pressure pattern of the hand at (a across, b along); 0 off the hand.
  double hand_pressure(const Subject& s, double a, double b, double span, double palm_half) const {
    if (b >= 0.0) {  // palm
      if (b > cfg_.palm_length || std::fabs(a) > palm_half) return 0.0;
      // Rounded heel corners.
      const double corner = std::max(0.0, std::fabs(a) - (palm_half - 3.0));
      const double heel_edge = std::max(0.0, b - (cfg_.palm_length - 3.0));
      const double rim = 3.0 - std::sqrt(corner * corner + heel_edge * heel_edge);
      if (rim <= 0.0) return 0.0;
      // Distance to the palm outline (the finger side joins the fingers and has no rim).
      const double d = std::min({rim, palm_half - std::fabs(a), cfg_.palm_length - b});
      return taper(d) * (0.9 + 0.15 * s.heel * (b / cfg_.palm_length));
    }
    // Fingers: strip index from the left edge of the span.
    const double x = a + 0.5 * span;
    if (x < 0.0 || x > span) return 0.0;
    const double pitch = s.finger_width + s.finger_gap;
    const int f = static_cast<int>(x / pitch);
    if (f >= cfg_.fingers) return 0.0;
    const double in = x - f * pitch;
    if (in > s.finger_width) return 0.0;  // the gap between fingers
    const double len = cfg_.finger_length * s.finger_length[static_cast<std::size_t>(f)];
    if (-b > len) return 0.0;
    // Creases between phalanges press less; the distal pad presses more.
    const double t = -b / len;
    const double crease = 1.0 - 0.35 * std::exp(-0.5 * std::pow((t - 0.5) / 0.05, 2));
    const double d = std::min({in, s.finger_width - in, len + b});
    return taper(d) * crease * (0.85 + 0.25 * s.pads * t);
  }

  // Soft tissue: contact pressure falls to zero at the outline of the contact patch like a
  // Hertzian profile, sqrt(d / rim) within `rim` tactels of the edge.
  double taper(double d) const noexcept {
    if (cfg_.rim <= 0.0) return 1.0;
    return d >= cfg_.rim ? 1.0 : std::sqrt(std::max(0.0, d) / cfg_.rim);
  }

  static std::uint64_t mix(std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) {
    std::uint64_t h = a * 0x9e3779b97f4a7c15ULL;
    for (std::uint64_t v : {b, c, d}) {
      h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
      h *= 0xbf58476d1ce4e5b9ULL;
      h ^= h >> 31;
    }
    return h;
  }

  PalmGraspConfig cfg_;
  std::uint64_t seed_;
};

}  // namespace taxel::sim
