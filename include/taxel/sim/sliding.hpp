// SPDX-License-Identifier: MIT
// A sliding exploration: a tactile pad slides over a shape and streams noisy contacts.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "taxel/core/contact.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// Parameters of a sliding exploration. Defaults: a 3x3 patch of a 3.4 mm-pitch pad in
/// contact, sliding at 20 mm/s, 1 kHz frames.
struct SlidingConfig {
  double pitch = 3.4e-3;           ///< tactel pitch [m]
  int rows = 3;                    ///< tactel rows of the patch in contact, >= 1
  int cols = 3;                    ///< tactel columns of the patch in contact, >= 1
  double speed = 0.02;             ///< sliding speed [m/s]
  double frame_rate = 1000.0;      ///< frames per second [Hz]
  double heading_sigma = 0.05;     ///< random-walk step of the sliding direction [rad/frame]
  double sigma_normal = 1.0e-3;    ///< contact noise along the pad normal [m]
  double sigma_position = 0.2e-3;  ///< kinematic translation noise per frame [m]
  double sigma_tilt = 0.05;        ///< kinematic orientation noise per frame [rad]
  double contact_depth = 1.5e-3;  ///< a tactel touches when within this distance of the surface [m]
  std::uint64_t seed = 1;         ///< random seed; equal seeds give equal streams
};

/// `count` contacts of a pad sliding over `shape` (in the shape's frame). Each frame moves the
/// pad along the surface, perturbs its believed pose (kinematic noise shared by the frame),
/// and reports every touching tactel: the surface point under it, shifted by tactel
/// quantisation (uniform over one pitch in the pad plane) and by normal noise. Each contact
/// carries the pad covariance it was drawn with (sigma_normal along the believed normal,
/// pitch / sqrt(12) across, both widened by sigma_position) and the frame time.
/// Deterministic for a given seed. Throws std::invalid_argument for invalid parameters.
template <Shape Sh>
std::vector<Contact<double>> sliding_exploration(const Sh& shape, std::size_t count,
                                                 const SlidingConfig& cfg = {}) {
  if (!(cfg.pitch > 0) || cfg.rows < 1 || cfg.cols < 1 || !(cfg.frame_rate > 0) ||
      !(cfg.speed >= 0) || !(cfg.sigma_normal > 0) || !(cfg.sigma_position >= 0) ||
      !(cfg.sigma_tilt >= 0) || !(cfg.heading_sigma >= 0) || !(cfg.contact_depth > 0)) {
    throw std::invalid_argument(
        "sliding_exploration: pitch, frame_rate, sigma_normal, contact_depth must be > 0, "
        "rows and cols >= 1, the other sigmas and speed >= 0");
  }
  std::mt19937_64 rng(cfg.seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(-0.5, 0.5);

  const double sigma_t = std::hypot(tactel_sigma(cfg.pitch), cfg.sigma_position);
  const double sigma_n = std::hypot(cfg.sigma_normal, cfg.sigma_position);
  const double step = cfg.speed / cfg.frame_rate;

  // Start on the surface above a random direction.
  Vec3d start(gauss(rng), gauss(rng), gauss(rng));
  Vec3d p = shape.closest_point(start.normalized() * 10.0);
  Vec3d n = shape.normal(p);
  Vec3d heading = n.unitOrthogonal();

  std::vector<Contact<double>> out;
  out.reserve(count);
  for (std::size_t frame = 0; out.size() < count; ++frame) {
    const double time = static_cast<double>(frame) / cfg.frame_rate;
    const Vec3d side = n.cross(heading);
    // The pose the robot believes the pad has: the true one perturbed.
    const Eigen::AngleAxisd tilt(cfg.sigma_tilt * gauss(rng),
                                 Vec3d(gauss(rng), gauss(rng), gauss(rng)).normalized());
    const Vec3d shift(cfg.sigma_position * gauss(rng), cfg.sigma_position * gauss(rng),
                      cfg.sigma_position * gauss(rng));
    const Vec3d believed_normal = tilt * n;
    const Mat3d cov = pad_covariance(believed_normal, sigma_n, sigma_t);
    for (int i = 0; i < cfg.rows && out.size() < count; ++i) {
      for (int j = 0; j < cfg.cols && out.size() < count; ++j) {
        const double u = (i - 0.5 * (cfg.rows - 1)) * cfg.pitch;
        const double v = (j - 0.5 * (cfg.cols - 1)) * cfg.pitch;
        const Vec3d tactel = p + u * heading + v * side;
        if (std::abs(shape.signed_distance(tactel)) > cfg.contact_depth) continue;
        const Vec3d surface = shape.closest_point(tactel);
        const Vec3d local = surface + cfg.pitch * (uniform(rng) * heading + uniform(rng) * side) +
                            cfg.sigma_normal * gauss(rng) * n;
        Contact<double> c;
        c.position = p + shift + tilt * (local - p);
        c.covariance = cov;
        c.normal = believed_normal;
        c.pressure = 1.0;
        c.time = time;
        out.push_back(c);
      }
    }
    // Slide: random-walk heading, step along it, back onto the surface.
    heading = Eigen::AngleAxisd(cfg.heading_sigma * gauss(rng), n) * heading;
    p = shape.closest_point(p + step * heading);
    const Vec3d n_new = shape.normal(p);
    Vec3d h = heading - heading.dot(n_new) * n_new;
    heading = h.norm() > 1e-9 ? Vec3d(h.normalized()) : n_new.unitOrthogonal();
    n = n_new;
  }
  return out;
}

/// Distances of points to a shape's surface [m].
struct SurfaceError {
  double signed_mean = 0;  ///< mean signed distance (outside positive): the bias
  double mean = 0;         ///< mean |signed distance|
  double rms = 0;          ///< root mean square signed distance
  double max = 0;          ///< largest |signed distance|
};

/// Signed mean, mean, RMS and max distance of `points` to the surface of `shape`; zeros for no
/// points.
template <Shape Sh, class Points>
SurfaceError surface_error(const Sh& shape, const Points& points) {
  SurfaceError e;
  std::size_t n = 0;
  for (const auto& p : points) {
    const double sd = shape.signed_distance(p.template cast<double>());
    const double d = std::abs(sd);
    e.signed_mean += sd;
    e.mean += d;
    e.rms += d * d;
    e.max = std::max(e.max, d);
    ++n;
  }
  if (n > 0) {
    e.signed_mean /= double(n);
    e.mean /= double(n);
    e.rms = std::sqrt(e.rms / double(n));
  }
  return e;
}

}  // namespace taxel::sim
