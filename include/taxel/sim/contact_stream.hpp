// SPDX-License-Identifier: MIT
// Contact streams of the kind other pipelines produce (a kinematic model, a vision-based sensor,
// another simulator), as a check on fusion that taxel's own pad model cannot give: each contact
// states an anisotropic covariance and its position scatters accordingly, its normal is the
// true surface normal turned by noise that it does not state (normal_sigma 0), and every frame
// carries a pose error that no covariance states.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/sim/compression.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// Options of contact_stream. Lengths in metres, angles in radians.
struct ContactStreamConfig {
  std::size_t contacts = 200000;  ///< stop after this many contacts, >= 1
  int rows = 14;                  ///< contact sites per frame along the pad, >= 1
  int cols = 6;                   ///< and across it, >= 1
  double pitch = 3.4e-3;          ///< spacing of the sites, > 0
  double indentation = 1e-3;      ///< a site touches where the surface is this close, > 0
  double sigma_normal = 0.3e-3;   ///< stated and drawn along the true normal, > 0
  /// Drawn across the normal and stated there, >= 0; 0: no lateral scatter, and the stated
  /// covariance is sigma_normal^2 across as well.
  double sigma_lateral = 1.0e-3;
  double normal_noise = 0.05;  ///< the reported normal turns by this about each axis, >= 0
  /// Whether contacts state their normals' noise (normal_sigma = the per-axis tilt of the
  /// normal noise and the pose error, sqrt(normal_noise^2 + pose_angle^2 / 3)); otherwise 0.
  bool state_normal_sigma = false;
  /// 0: sharp normals (the true one at the contact). > 0: the normal is the mean of the true
  /// normals over a square of this half side around the contact in its tangent plane (3 x 3
  /// points), as a normal taken from a depth map is: it rounds a crease over that width.
  double normal_smoothing = 0.0;
  /// Samples per side of a site's pitch x pitch footprint, in [1, 4]: 1 reads the surface at
  /// the site; n >= 2 reads the mean compression over the footprint along the pad normal (n x n
  /// Gauss-Legendre points, a sample that does not touch reading 0), as a tactel does, and
  /// places the contact at the site pushed back by that mean.
  int footprint = 1;
  double pose_position = 0.2e-3;  ///< per-frame pose error, translation per axis, >= 0
  double pose_angle = 0.02;       ///< and rotation about a random axis, >= 0
  int stroke_frames = 20;         ///< frames of a stroke, >= 1 (a press has one)
  double stroke_step = 1e-3;      ///< how far a stroke moves per frame, >= 0
  double press_share = 0.5;       ///< share of presses among the touches, in [0, 1]
  std::uint64_t seed = 1;         ///< equal seeds, equal streams

  /// Throws std::invalid_argument naming the first field out of range.
  void validate() const {
    const auto need = [](bool ok, const char* what) {
      if (!ok) throw std::invalid_argument(std::string("ContactStreamConfig: ") + what);
    };
    need(contacts >= 1, "contacts must be >= 1");
    need(rows >= 1 && cols >= 1 && rows <= 4096 && cols <= 4096, "rows and cols in [1, 4096]");
    need(pitch > 0 && pitch <= 1, "pitch in (0, 1] m");
    need(indentation > 0 && indentation <= 1, "indentation in (0, 1] m");
    need(sigma_normal > 0 && sigma_normal <= 1, "sigma_normal in (0, 1] m");
    need(sigma_lateral >= 0 && sigma_lateral <= 1, "sigma_lateral in [0, 1] m");
    need(normal_smoothing >= 0 && normal_smoothing <= 1, "normal_smoothing in [0, 1] m");
    need(footprint >= 1 && footprint <= 4, "footprint in [1, 4] samples per side");
    need(normal_noise >= 0 && normal_noise <= 1, "normal_noise in [0, 1] rad");
    need(pose_position >= 0 && pose_position <= 1, "pose_position in [0, 1] m");
    need(pose_angle >= 0 && pose_angle <= 1, "pose_angle in [0, 1] rad");
    need(stroke_frames >= 1 && stroke_frames <= 1000000, "stroke_frames in [1, 1e6]");
    need(stroke_step >= 0 && stroke_step <= 1, "stroke_step in [0, 1] m");
    need(press_share >= 0 && press_share <= 1, "press_share in [0, 1]");
  }
};

/// A contact stream of presses and sliding strokes over `shape` (see the file comment). Each
/// touch starts at an area-uniform surface point; a pad of rows x cols sites, `pitch` apart, lies
/// in the tangent plane there, and each site within `indentation` of the surface gives a contact
/// at the surface point closest to it, scattered by N(0, Sigma) with Sigma = sigma_normal^2 n n'
/// + sigma_lateral^2 (I - n n') (n the true normal), which the contact states. Its normal is n
/// turned by N(0, normal_noise) about each axis, unstated. All of a frame's contacts then move
/// with the frame's pose error (about the touch point), unstated too. Time advances by 1 ms per
/// frame. Deterministic for a seed. Throws std::invalid_argument for a bad configuration.
template <SampleableShape Sh>
std::vector<Contact<double>> contact_stream(const Sh& shape, const ContactStreamConfig& cfg) {
  cfg.validate();
  std::mt19937_64 rng(cfg.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Contact<double>> out;
  out.reserve(cfg.contacts);
  const auto small_rotation = [&](double sigma) {
    return Eigen::Matrix3d(Eigen::AngleAxisd(sigma * gauss(rng), Vec3d::UnitX()) *
                           Eigen::AngleAxisd(sigma * gauss(rng), Vec3d::UnitY()) *
                           Eigen::AngleAxisd(sigma * gauss(rng), Vec3d::UnitZ()));
  };
  double time = 0.0;
  std::size_t touches = 0;
  while (out.size() < cfg.contacts) {
    if (++touches > 100 * cfg.contacts + 1000) {
      throw std::invalid_argument("contact_stream: the pad hardly ever touches the shape");
    }
    Vec3d p, n;
    sample_point(shape, rng, p, n);
    // The pad's axes in the tangent plane, turned by a random heading.
    Vec3d u = n.unitOrthogonal();
    const double heading = 2.0 * std::numbers::pi * unit(rng);
    u = Eigen::AngleAxisd(heading, n) * u;
    const bool press = unit(rng) < cfg.press_share;
    const int frames = press ? 1 : cfg.stroke_frames;
    for (int f = 0; f < frames && out.size() < cfg.contacts; ++f, time += 1e-3) {
      // The pad slides along u, staying tangent to the surface under its centre.
      const Vec3d centre = shape.closest_point(p + u * (cfg.stroke_step * f));
      const Vec3d nc = shape.normal(centre);
      const Vec3d uc = (u - nc * nc.dot(u)).normalized();
      const Vec3d vc = nc.cross(uc);
      if (!uc.allFinite()) break;
      Eigen::Matrix3d pose_rotation =
          Eigen::AngleAxisd(cfg.pose_angle * gauss(rng),
                            Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized())
              .toRotationMatrix();
      if (!pose_rotation.allFinite()) pose_rotation.setIdentity();
      const Vec3d pose_shift(cfg.pose_position * gauss(rng), cfg.pose_position * gauss(rng),
                             cfg.pose_position * gauss(rng));
      for (int r = 0; r < cfg.rows; ++r) {
        for (int c = 0; c < cfg.cols; ++c) {
          const Vec3d site =
              centre +
              cfg.pitch * ((c - 0.5 * (cfg.cols - 1)) * vc + (r - 0.5 * (cfg.rows - 1)) * uc) -
              cfg.indentation * nc;
          Vec3d q;
          if (cfg.footprint == 1) {
            if (!(shape.signed_distance(site) < 0.0)) continue;  // this site does not touch
            q = shape.closest_point(site);
          } else {
            // The mean compression over the footprint (read_pad's model), the site pushed back
            // by it.
            const int k = cfg.footprint - 1;
            double depth = 0.0;
            bool touching = false;
            for (int i = 0; i < cfg.footprint; ++i) {
              for (int j = 0; j < cfg.footprint; ++j) {
                const Vec3d at = site + cfg.pitch * (kGaussNode[k][i] * uc + kGaussNode[k][j] * vc);
                if (!(shape.signed_distance(at) < 0.0)) continue;
                touching = true;
                depth += kGaussWeight[k][i] * kGaussWeight[k][j] * compression(shape, at, nc);
              }
            }
            if (!touching) continue;
            q = site + depth * nc;
          }
          const Vec3d nq = shape.normal(q);
          const Vec3d t1 = nq.unitOrthogonal(), t2 = nq.cross(t1);
          const double across = cfg.sigma_lateral > 0 ? cfg.sigma_lateral : cfg.sigma_normal;
          Contact<double> k;
          k.position = q + cfg.sigma_normal * gauss(rng) * nq +
                       cfg.sigma_lateral * (gauss(rng) * t1 + gauss(rng) * t2);
          k.covariance = cfg.sigma_normal * cfg.sigma_normal * nq * nq.transpose() +
                         across * across * (Eigen::Matrix3d::Identity() - nq * nq.transpose());
          Vec3d truth = nq;
          if (cfg.normal_smoothing > 0) {
            const Vec3d cq = shape.closest_point(q);
            truth = Vec3d::Zero();
            for (int i = -1; i <= 1; ++i) {
              for (int j = -1; j <= 1; ++j) {
                truth += shape.normal(shape.closest_point(
                    cq + cfg.normal_smoothing * (double(i) * t1 + double(j) * t2)));
              }
            }
            truth.normalize();
          }
          Vec3d reported = small_rotation(cfg.normal_noise) * truth;
          // The frame's pose error moves the whole frame about the touch point.
          k.position = pose_rotation * (k.position - centre) + centre + pose_shift;
          reported = pose_rotation * reported;
          k.normal = reported.normalized();
          if (cfg.state_normal_sigma) {
            k.normal_sigma = std::sqrt(cfg.normal_noise * cfg.normal_noise +
                                       cfg.pose_angle * cfg.pose_angle / 3.0);
          }
          k.time = time;
          out.push_back(k);
          if (out.size() >= cfg.contacts) return out;
        }
      }
    }
  }
  return out;
}

}  // namespace taxel::sim
