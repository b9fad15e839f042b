// SPDX-License-Identifier: MIT
// A simulated tactile pad: a matrix of tactels pressed against a shape. Per-tactel readings by
// indentation with depth noise and the noise floor, and kinematic (pose) noise; the readings
// become contacts through the measurement model of sensor/contacts.hpp, as a real pad's do.
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
#include "taxel/sensor/contacts.hpp"
#include "taxel/sensor/pad.hpp"
#include "taxel/sim/compression.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// A shape placed in the world: `pose` maps the shape's frame to the world. Satisfies `Shape`
/// (and `SampleableShape` when the shape does), so metrics and explorations work in world
/// coordinates.
template <Shape Sh>
struct Posed {
  Sh shape;                                                ///< The shape in its own frame.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< Shape frame -> world.

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

using sensor::ContactMode;
using sensor::PadGeometry;
using sensor::PadMatrix;
using sensor::SensorModel;

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

/// Reads a pad pressed against `shape` (in world coordinates; wrap a placed shape in `Posed`)
/// at `true_pose`, drawing the frame's kinematic noise and the tactels' depth noise from `rng`.
/// A point of the pad inside the shape is compressed by the distance along the pad normal back
/// to the surface (`compression`).
///
/// `footprint` says where a tactel senses. 1: at its centre only, so that its contact, pushed
/// back by the reading, lies on the surface. n >= 2: the mean compression over the tactel's
/// pitch x pitch square (n x n Gauss-Legendre points, n <= 4; 2 is exact for a paraboloid), as
/// a real tactel averages over its area. On a convex surface of radius R a fully touching
/// tactel then reads pitch^2 / (12 R) less than at its centre, and a tactel partly off the
/// object reads its touching share. Throws std::invalid_argument for an invalid model or a
/// footprint outside [1, 4].
template <Shape Sh, class Rng>
PadReading read_pad(const Sh& shape, const SensorModel& model, const Eigen::Isometry3d& true_pose,
                    Rng& rng, int pad = 0, int footprint = 1) {
  model.validate();
  if (footprint < 1 || footprint > 4) {
    throw std::invalid_argument("read_pad: footprint must be in [1, 4] samples per side");
  }
  const int k = footprint - 1;
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
      double depth = 0.0;
      if (footprint == 1) {
        const Vec3d at = true_pose * g.tactel(r, c);
        if (!(shape.signed_distance(at) < 0.0)) continue;
        depth = compression(shape, at, back);
      } else {
        bool touching = false;
        for (int i = 0; i < footprint; ++i) {
          for (int j = 0; j < footprint; ++j) {
            const Vec3d at = true_pose * (g.tactel(r, c) +
                                          g.pitch * Vec3d(kGaussNode[k][j], kGaussNode[k][i], 0.0));
            if (!(shape.signed_distance(at) < 0.0)) continue;
            touching = true;
            depth += kGaussWeight[k][i] * kGaussWeight[k][j] * compression(shape, at, back);
          }
        }
        if (!touching) continue;
      }
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

/// Appends the contacts of `reading` to `out`, in the world frame given by the believed pose,
/// by the measurement model of sensor/contacts.hpp (`sensor::ContactExtractor`). Builds the
/// extractor's workspace on every call: a loop over many frames should keep one extractor.
/// Returns the number of contacts appended.
template <class = void>
inline std::size_t pad_contacts(const PadReading& reading, const SensorModel& model,
                                const sensor::ContactOptions& options, double time,
                                std::vector<Contact<double>>& out) {
  sensor::ContactExtractor extractor(model, options);
  return extractor.extract(reading.counts, reading.believed_pose, time, out);
}

/// As above with the default options and the given contact mode.
template <class = void>
inline std::size_t pad_contacts(const PadReading& reading, const SensorModel& model,
                                ContactMode mode, double time, std::vector<Contact<double>>& out) {
  return pad_contacts(reading, model, sensor::ContactOptions{.mode = mode}, time, out);
}

}  // namespace taxel::sim
