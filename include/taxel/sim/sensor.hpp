// SPDX-License-Identifier: MIT
// A tactile pad model: a matrix of tactels pressed against a shape. Per-tactel pressure by
// indentation, kinematic (pose) noise, depth noise along the pad normal and in-plane
// quantisation; contacts per active tactel or one pressure-weighted contact per pad, each with
// the anisotropic covariance its noise model implies.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/types.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// A shape placed in the world: `pose` maps the shape's frame to the world. Satisfies `Shape`
/// (and `SampleableShape` when the shape does), so metrics and explorations work in world
/// coordinates.
template <Shape Sh>
struct Posed {
  Sh shape;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();

  /// Signed distance of a world point [m].
  double signed_distance(const Vec3d& p) const { return shape.signed_distance(pose.inverse() * p); }
  /// Closest surface point, in the world.
  Vec3d closest_point(const Vec3d& p) const {
    return pose * shape.closest_point(pose.inverse() * p);
  }
  /// Outward normal at the closest point, in the world.
  Vec3d normal(const Vec3d& p) const { return pose.linear() * shape.normal(pose.inverse() * p); }
};

/// Surface area of a placed shape [m^2] (a rigid motion keeps it).
template <Shape Sh>
double surface_area(const Posed<Sh>& s) requires requires {
  surface_area(s.shape);
}
{ return surface_area(s.shape); }

/// Uniform surface point of a placed shape, in the world.
template <Shape Sh, class Rng>
auto sample_point(const Posed<Sh>& s, Rng& rng, Vec3d& p, Vec3d& n)
    -> decltype(sample_point(s.shape, rng, p, n)) {
  sample_point(s.shape, rng, p, n);
  p = s.pose * p;
  n = s.pose.linear() * n;
}

/// Tactel layout of a pad. Tactel (r, c) sits at x = (c - (cols - 1) / 2) pitch,
/// y = (r - (rows - 1) / 2) pitch, z = 0 in the pad frame; the sensing face looks along +z.
/// Default: a Weiss DSA 9205-like matrix, 14 rows x 6 columns at 3.4 mm (REFERENCES.md 6).
struct PadGeometry {
  int rows = 14;          ///< tactel rows, >= 1
  int cols = 6;           ///< tactel columns, >= 1
  double pitch = 3.4e-3;  ///< centre-to-centre distance [m], > 0

  /// Centre of tactel (r, c) in the pad frame [m].
  Vec3d tactel(int r, int c) const {
    return {(c - 0.5 * (cols - 1)) * pitch, (r - 0.5 * (rows - 1)) * pitch, 0.0};
  }
};

/// How a pad turns indentation into readings, and the noise of the reading and of the pose.
/// The pad is soft and the object rigid: a tactel pressed `d` into the object reads
/// `d / full_scale_depth * (levels - 1)` counts (a linear, Winkler-foundation model), rounded,
/// clipped at `levels - 1`; readings below `threshold` are zero.
struct SensorModel {
  PadGeometry geometry;
  double full_scale_depth = 3e-3;  ///< indentation that saturates a tactel [m], > 0
  int levels = 4096;               ///< reading levels (12-bit like the DSA), >= 2
  int threshold = 8;               ///< readings below this are zero (noise floor), >= 1
  double sigma_normal = 0.3e-3;    ///< depth noise of a touching tactel, along the normal [m]
  double sigma_position = 0.2e-3;  ///< kinematic translation noise of the pad, per frame [m]
  double sigma_tilt = 0.02;  ///< kinematic rotation noise of the pad, per frame: angle std [rad]

  /// Throws std::invalid_argument naming the first parameter out of range.
  void validate() const {
    const auto need = [](bool ok, const char* what) {
      if (!ok) throw std::invalid_argument(std::string("SensorModel: ") + what);
    };
    need(geometry.rows >= 1 && geometry.cols >= 1, "rows and cols must be >= 1");
    need(geometry.rows <= 4096 && geometry.cols <= 4096, "rows and cols must be <= 4096");
    need(geometry.pitch > 0 && std::isfinite(geometry.pitch), "pitch must be finite and > 0");
    need(full_scale_depth > 0 && std::isfinite(full_scale_depth),
         "full_scale_depth must be finite and > 0");
    need(levels >= 2 && levels <= 65536, "levels must be in [2, 65536]");
    need(threshold >= 1 && threshold < levels, "threshold must be in [1, levels)");
    need(sigma_normal >= 0 && std::isfinite(sigma_normal), "sigma_normal must be finite, >= 0");
    need(sigma_position >= 0 && std::isfinite(sigma_position),
         "sigma_position must be finite, >= 0");
    need(sigma_tilt >= 0 && std::isfinite(sigma_tilt), "sigma_tilt must be finite, >= 0");
  }
};

/// Readings of one pad as a row-major rows x cols matrix of counts.
using PadMatrix = Eigen::Array<std::uint16_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// One frame of one pad: its readings and its pose, true and as the robot believes it.
struct PadReading {
  int pad = 0;                                                  ///< pad id within the hand
  PadMatrix counts;                                             ///< rows x cols readings
  Eigen::Isometry3d true_pose = Eigen::Isometry3d::Identity();  ///< pad -> world, exact
  /// pad -> world as forward kinematics reports it (true pose with kinematic noise)
  Eigen::Isometry3d believed_pose = Eigen::Isometry3d::Identity();
  /// True when some tactel reads above the threshold.
  bool touching() const { return (counts > 0).any(); }
};

/// Contacts from a reading: one per active tactel, or one pressure-weighted contact per pad.
enum class ContactMode { per_tactel, per_pad };

/// How far a tactel at `at`, inside the shape, is pushed back along `back` (unit) until it leaves
/// the shape: the pad's compression there [m]. Sphere tracing: each step moves by the distance to
/// the surface, which never overshoots it.
template <Shape Sh>
double compression(const Sh& shape, const Vec3d& at, const Vec3d& back) {
  double t = 0.0;
  for (int it = 0; it < 200; ++it) {
    const double d = -shape.signed_distance(at + t * back);
    if (d <= 1e-12) break;
    t += std::max(d, 1e-10);
  }
  return t;
}

/// Reads a pad pressed against `shape` (in world coordinates; wrap a placed shape in `Posed`)
/// at `true_pose`, drawing the frame's kinematic noise and the tactels' depth noise from `rng`.
/// A tactel inside the shape is compressed by the distance along the pad normal back to the
/// surface (`compression`); its contact, pushed back that far, lies on the surface.
/// Throws std::invalid_argument for an invalid model.
template <Shape Sh, class Rng>
PadReading read_pad(const Sh& shape, const SensorModel& model, const Eigen::Isometry3d& true_pose,
                    Rng& rng, int pad = 0) {
  model.validate();
  std::normal_distribution<double> gauss(0.0, 1.0);
  const PadGeometry& g = model.geometry;
  PadReading out;
  out.pad = pad;
  out.true_pose = true_pose;
  out.counts.setZero(g.rows, g.cols);
  const double scale = double(model.levels - 1) / model.full_scale_depth;
  const Vec3d back = -true_pose.linear().col(2);
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c) {
      const Vec3d at = true_pose * g.tactel(r, c);
      if (!(shape.signed_distance(at) < 0.0)) continue;
      const double depth = compression(shape, at, back);
      const double measured = depth + model.sigma_normal * gauss(rng);
      const double counts = std::min(std::round(measured * scale), double(model.levels - 1));
      if (counts >= model.threshold) out.counts(r, c) = static_cast<std::uint16_t>(counts);
    }
  }
  // The pose the robot believes: the true one turned by a random small rotation about the pad
  // origin and shifted.
  Vec3d axis(gauss(rng), gauss(rng), gauss(rng));
  axis = axis.norm() > 0 ? Vec3d(axis.normalized()) : Vec3d::UnitZ();
  const double angle = model.sigma_tilt * gauss(rng);
  const Vec3d shift(model.sigma_position * gauss(rng), model.sigma_position * gauss(rng),
                    model.sigma_position * gauss(rng));
  out.believed_pose = true_pose;
  out.believed_pose.linear() = true_pose.linear() * Eigen::AngleAxisd(angle, axis).matrix();
  out.believed_pose.translation() += shift;
  return out;
}

/// Appends the contacts of `reading` to `out`, in the world frame given by the believed pose.
/// A tactel reading k counts is taken as the pad surface pushed back by
/// k / (levels - 1) * full_scale_depth along the pad normal; its contact sits there. Saturated
/// tactels (levels - 1) carry no depth and give no per-tactel contact. The contact normal is the
/// surface normal the pad implies: -z of the believed pad frame. Covariance (pad_covariance):
///  - along the normal: sigma_normal, depth quantisation, sigma_position and the lever arm of the
///    tilt noise (|xy| sigma_tilt / sqrt(3));
///  - across: in-plane quantisation pitch / sqrt(12), sigma_position and the tilt lever arm
///    (|xy| sigma_tilt / sqrt(6)).
/// per_pad: one contact at the reading-weighted mean of the non-saturated tactels' points, the
/// normal variance divided by their count, the in-plane sigma that of one tactel. Returns the
/// number of contacts appended.
inline std::size_t pad_contacts(const PadReading& reading, const SensorModel& model,
                                ContactMode mode, double time, std::vector<Contact<double>>& out) {
  const PadGeometry& g = model.geometry;
  const int saturated = model.levels - 1;
  const double depth_per_count = model.full_scale_depth / double(saturated);
  const Vec3d normal = -reading.believed_pose.linear().col(2);
  const double s_quant = tactel_sigma(g.pitch);
  const double s_depth = tactel_sigma(depth_per_count);
  const double st2 = model.sigma_tilt * model.sigma_tilt;
  const double sp2 = model.sigma_position * model.sigma_position;
  const auto make = [&](const Vec3d& local, double normal_var, double pressure) {
    const double lever2 = local.head<2>().squaredNorm();
    Contact<double> c;
    c.position = reading.believed_pose * local;
    c.covariance = pad_covariance(normal, std::sqrt(normal_var + sp2 + lever2 * st2 / 3.0),
                                  std::sqrt(s_quant * s_quant + sp2 + lever2 * st2 / 6.0));
    c.normal = normal;
    c.pressure = pressure;
    c.time = time;
    return c;
  };
  const double var_n = model.sigma_normal * model.sigma_normal + s_depth * s_depth;
  std::size_t added = 0;
  Vec3d sum = Vec3d::Zero();
  double weight = 0.0;
  int used = 0;
  for (int r = 0; r < g.rows; ++r) {
    for (int c = 0; c < g.cols; ++c) {
      const int k = reading.counts(r, c);
      if (k == 0 || k >= saturated) continue;
      Vec3d local = g.tactel(r, c);
      local.z() = -double(k) * depth_per_count;
      if (mode == ContactMode::per_tactel) {
        out.push_back(make(local, var_n, double(k)));
        ++added;
      } else {
        sum += double(k) * local;
        weight += double(k);
        ++used;
      }
    }
  }
  if (mode == ContactMode::per_pad && used > 0) {
    out.push_back(make(sum / weight, var_n / used, weight));
    ++added;
  }
  return added;
}

}  // namespace taxel::sim
