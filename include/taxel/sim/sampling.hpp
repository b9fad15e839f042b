// SPDX-License-Identifier: MIT
// Surface sampling of the analytic shapes: uniform (area-weighted) point clouds with exact
// normals, for ICP models and ground truth; and partial "tactile" clouds made of a few touched
// patches with noise, like the clouds a hand gathers.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/point_cloud.hpp"
#include "taxel/sim/shapes.hpp"

namespace taxel::sim {

/// Surface area [m^2].
inline double surface_area(const Sphere& s) { return 4.0 * std::numbers::pi * s.radius * s.radius; }
/// Surface area [m^2] (side and both caps).
inline double surface_area(const Cylinder& c) {
  return 2.0 * std::numbers::pi * c.radius * (2.0 * c.half_height + c.radius);
}
/// Surface area [m^2].
inline double surface_area(const Box& b) {
  const Vec3d e = 2.0 * b.half_extents;
  return 2.0 * (e.x() * e.y() + e.y() * e.z() + e.z() * e.x());
}

/// Surface area [m^2] (slanted side and base).
inline double surface_area(const Cone& c) {
  return std::numbers::pi * c.radius * (c.radius + std::hypot(c.radius, c.height));
}

/// One point drawn uniformly over the surface (by area), with its outward normal.
template <class Rng>
void sample_point(const Sphere& s, Rng& rng, Vec3d& p, Vec3d& n) {
  std::normal_distribution<double> g(0.0, 1.0);
  Vec3d d(g(rng), g(rng), g(rng));
  while (d.squaredNorm() < 1e-24) d = Vec3d(g(rng), g(rng), g(rng));
  n = d.normalized();
  p = s.radius * n;
}

template <class Rng>
void sample_point(const Cylinder& c, Rng& rng, Vec3d& p, Vec3d& n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double side = 2.0 * std::numbers::pi * c.radius * 2.0 * c.half_height;
  const double cap = std::numbers::pi * c.radius * c.radius;
  const double pick = u(rng) * (side + 2.0 * cap);
  const double phi = 2.0 * std::numbers::pi * u(rng);
  if (pick < side) {
    n = Vec3d(std::cos(phi), std::sin(phi), 0.0);
    p = Vec3d(c.radius * n.x(), c.radius * n.y(), c.half_height * (2.0 * u(rng) - 1.0));
    return;
  }
  const double r = c.radius * std::sqrt(u(rng));  // uniform over the disc
  const double z = pick < side + cap ? c.half_height : -c.half_height;
  p = Vec3d(r * std::cos(phi), r * std::sin(phi), z);
  n = Vec3d(0.0, 0.0, z > 0 ? 1.0 : -1.0);
}

template <class Rng>
void sample_point(const Box& b, Rng& rng, Vec3d& p, Vec3d& n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const Vec3d h = b.half_extents;
  const std::array<double, 3> face{h.y() * h.z(), h.x() * h.z(), h.x() * h.y()};  // per axis
  double pick = u(rng) * 2.0 * (face[0] + face[1] + face[2]);
  int axis = 0;
  while (axis < 2 && pick >= 2.0 * face[static_cast<std::size_t>(axis)]) {
    pick -= 2.0 * face[static_cast<std::size_t>(axis)];
    ++axis;
  }
  const double sign = pick < face[static_cast<std::size_t>(axis)] ? 1.0 : -1.0;
  for (int k = 0; k < 3; ++k) p[k] = h[k] * (2.0 * u(rng) - 1.0);
  p[axis] = sign * h[axis];
  n = Vec3d::Zero();
  n[axis] = sign;
}

template <class Rng>
void sample_point(const Cone& c, Rng& rng, Vec3d& p, Vec3d& n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double slant = std::hypot(c.radius, c.height);
  const double side = std::numbers::pi * c.radius * slant;
  const double base = std::numbers::pi * c.radius * c.radius;
  const double phi = 2.0 * std::numbers::pi * u(rng);
  const Vec3d radial(std::cos(phi), std::sin(phi), 0.0);
  if (u(rng) * (side + base) < side) {
    // Area on the side grows linearly with the distance from the apex.
    const double t = std::sqrt(u(rng));  // fraction of the way from apex to rim
    p = t * c.radius * radial + Vec3d(0, 0, 0.5 * c.height - t * c.height);
    n = (c.height * radial + Vec3d(0, 0, c.radius)).normalized();
    return;
  }
  p = c.radius * std::sqrt(u(rng)) * radial + Vec3d(0, 0, -0.5 * c.height);
  n = Vec3d(0, 0, -1);
}

/// Surface area [m^2]: 4 pi^2 R r.
inline double surface_area(const Torus& t) {
  return 4.0 * std::numbers::pi * std::numbers::pi * t.major_radius * t.minor_radius;
}

/// Surface area [m^2], by quadrature. With w = cos u, the area element of
/// x = (a sin u cos v, b sin u sin v, c w) is
/// sqrt((1 - w^2)(b^2 c^2 cos^2 v + a^2 c^2 sin^2 v) + a^2 b^2 w^2) dw dv, smooth on
/// [-1, 1] x [0, 2 pi): 256 midpoint nodes in v (spectrally accurate for a periodic integrand)
/// times 64-point Gauss-Legendre in w.
inline double surface_area(const Ellipsoid& el) {
  const double a = el.semi_axes.x(), b = el.semi_axes.y(), c = el.semi_axes.z();
  // Gauss-Legendre nodes on [-1, 1] by Newton's method on P_n (Golub-Welsch is overkill here).
  constexpr int m = 64, nv = 256;
  std::array<double, m> x{}, w{};
  for (int i = 0; i < m; ++i) {
    double t = std::cos(std::numbers::pi * (i + 0.75) / (m + 0.5));
    double dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = t;
      for (int k = 2; k <= m; ++k) {
        const double p2 = ((2.0 * k - 1.0) * t * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = m * (t * p1 - p0) / (t * t - 1.0);
      const double step = p1 / dp;
      t -= step;
      if (std::abs(step) < 1e-16) break;
    }
    x[static_cast<std::size_t>(i)] = t;
    w[static_cast<std::size_t>(i)] = 2.0 / ((1.0 - t * t) * dp * dp);
  }
  const double dv = 2.0 * std::numbers::pi / nv;
  double sum = 0.0;
  for (int j = 0; j < nv; ++j) {
    const double v = (j + 0.5) * dv, sv = std::sin(v), cv = std::cos(v);
    const double lateral = b * b * c * c * cv * cv + a * a * c * c * sv * sv;
    for (int i = 0; i < m; ++i) {
      const double t = x[static_cast<std::size_t>(i)];
      sum += w[static_cast<std::size_t>(i)] *
             std::sqrt((1.0 - t * t) * lateral + a * a * b * b * t * t);
    }
  }
  return sum * dv;
}

/// Area-uniform point on the ellipsoid: a uniform direction u scaled to the surface, accepted
/// with probability proportional to the area element |(u_x / a, u_y / b, u_z / c)| a b c
/// relative to its maximum (rejection sampling, exact).
template <class Rng>
void sample_point(const Ellipsoid& el, Rng& rng, Vec3d& p, Vec3d& n) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const Vec3d& e = el.semi_axes;
  const double gmax = e.prod() / e.minCoeff();
  for (;;) {
    Vec3d d(g(rng), g(rng), g(rng));
    if (d.squaredNorm() < 1e-24) continue;
    d.normalize();
    const Vec3d grad = d.cwiseQuotient(e);
    if (u01(rng) * gmax > e.prod() * grad.norm()) continue;
    p = e.cwiseProduct(d);
    n = grad.normalized();
    return;
  }
}

/// Area-uniform point on the torus: the angle around the axis uniform, the angle around the
/// tube accepted with probability (R + r cos theta) / (R + r).
template <class Rng>
void sample_point(const Torus& t, Rng& rng, Vec3d& p, Vec3d& n) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double R = t.major_radius, r = t.minor_radius;
  double theta = 0.0;
  do {
    theta = 2.0 * std::numbers::pi * u01(rng);
  } while (u01(rng) * (R + r) > R + r * std::cos(theta));
  const double phi = 2.0 * std::numbers::pi * u01(rng);
  const Vec3d radial(std::cos(phi), std::sin(phi), 0.0);
  n = std::cos(theta) * radial + Vec3d(0, 0, std::sin(theta));
  p = R * radial + r * n;
}

/// Surface area [m^2].
inline double surface_area(const TriangleMesh& m) { return m.surface_area(); }

/// Area-weighted uniform point on a mesh (the triangle by binary search of the cumulative
/// areas, then a uniform point in it), with the triangle's normal.
template <class Rng>
void sample_point(const TriangleMesh& m, Rng& rng, Vec3d& p, Vec3d& n) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::size_t f = m.face_at(u(rng));
  double s = u(rng), t = u(rng);
  if (s + t > 1.0) {
    s = 1.0 - s;
    t = 1.0 - t;
  }
  const auto& tri = m.triangles()[f];
  const auto& v = m.vertices();
  p = v[tri[0]] + s * (v[tri[1]] - v[tri[0]]) + t * (v[tri[2]] - v[tri[0]]);
  n = m.face_normal(f);
}

/// Concept of a shape that sample_point can draw from.
template <class Sh>
concept SampleableShape = Shape<Sh> && requires(const Sh& s, std::mt19937_64& rng, Vec3d& v) {
  sample_point(s, rng, v, v);
};

/// `count` points drawn uniformly over the surface with their exact outward normals.
/// Deterministic for a seed.
template <SampleableShape Sh>
PointCloud<double> sample_surface(const Sh& shape, std::size_t count, std::uint64_t seed = 1) {
  std::mt19937_64 rng(seed);
  PointCloud<double> cloud;
  cloud.points.resize(count);
  cloud.normals.resize(count);
  for (std::size_t i = 0; i < count; ++i)
    sample_point(shape, rng, cloud.points[i], cloud.normals[i]);
  return cloud;
}

/// About one point per `spacing`^2 of surface (ceil(area / spacing^2), at least 1), drawn as
/// sample_surface draws them: the cloud a model file's surface stands for, whatever the density
/// of its vertices. Throws std::invalid_argument for a spacing that is not finite and > 0, or one
/// that would need more than `max_points` points (the message names the spacing that fits).
template <SampleableShape Sh>
PointCloud<double> sample_surface_spacing(const Sh& shape, double spacing, std::uint64_t seed = 1,
                                          std::size_t max_points = std::size_t{1} << 22) {
  if (!(spacing > 0.0) || !std::isfinite(spacing)) {
    throw std::invalid_argument("sample_surface_spacing: spacing must be finite and > 0");
  }
  const double area = surface_area(shape);
  const double count = std::max(1.0, std::ceil(area / (spacing * spacing)));
  if (!(count <= static_cast<double>(max_points))) {
    throw std::invalid_argument("sample_surface_spacing: a surface of " + std::to_string(area) +
                                " m^2 at spacing " + std::to_string(spacing) + " m needs " +
                                std::to_string(count) + " points, more than " +
                                std::to_string(max_points) + "; a spacing of " +
                                std::to_string(std::sqrt(area / static_cast<double>(max_points))) +
                                " m or more fits (coordinates in millimetres? taxel uses metres)");
  }
  return sample_surface(shape, static_cast<std::size_t>(count), seed);
}

/// What a hand touching an object a few times gathers.
struct PatchConfig {
  int patches = 5;            ///< touched patches, >= 1
  double radius = 0.015;      ///< patch radius [m], > 0
  std::size_t points = 2000;  ///< points in the cloud, >= 1
  double sigma = 1e-3;        ///< isotropic Gaussian noise [m], >= 0
};

/// A partial cloud of `cfg.points` points: patch centres drawn uniformly over the surface, and
/// points drawn uniformly over the surface within `radius` (Euclidean) of some centre, plus
/// noise. Exact normals of the noise-free points. Deterministic for a seed. Throws
/// std::invalid_argument for a bad configuration.
template <SampleableShape Sh>
PointCloud<double> tactile_patches(const Sh& shape, const PatchConfig& cfg,
                                   std::uint64_t seed = 1) {
  if (cfg.patches < 1 || !(cfg.radius > 0) || cfg.points < 1 || !(cfg.sigma >= 0) ||
      !std::isfinite(cfg.radius) || !std::isfinite(cfg.sigma)) {
    throw std::invalid_argument(
        "PatchConfig: patches and points must be >= 1, radius > 0 and sigma >= 0 (finite)");
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<int> which(0, cfg.patches - 1);
  std::vector<Vec3d> centres(static_cast<std::size_t>(cfg.patches));
  Vec3d p, n;
  for (auto& c : centres) sample_point(shape, rng, c, n);
  PointCloud<double> cloud;
  cloud.points.reserve(cfg.points);
  cloud.normals.reserve(cfg.points);
  const double r2 = cfg.radius * cfg.radius;
  // Rejection sampling per patch keeps the density uniform over each patch's surface. A patch
  // smaller than the object's sampling density would starve; give up after many misses.
  std::size_t misses = 0;
  while (cloud.points.size() < cfg.points) {
    const Vec3d& c = centres[static_cast<std::size_t>(which(rng))];
    sample_point(shape, rng, p, n);
    if ((p - c).squaredNorm() > r2) {
      if (++misses > 1000 * cfg.points + 100000) {
        throw std::invalid_argument("tactile_patches: the patches are too small for the shape");
      }
      continue;
    }
    cloud.points.push_back(p + cfg.sigma * Vec3d(g(rng), g(rng), g(rng)));
    cloud.normals.push_back(n);
  }
  return cloud;
}

}  // namespace taxel::sim
