// SPDX-License-Identifier: MIT
// Analytic shapes with exact closest point, signed distance and outward normal.
#pragma once

#include <algorithm>
#include <cmath>
#include <concepts>
#include <stdexcept>

#include "taxel/core/types.hpp"

namespace taxel::sim {

/// A solid with an exact surface query, in its own frame (metres):
/// `closest_point(p)` on the surface, `signed_distance(p)` (negative inside) and
/// `normal(p)`, the outward unit normal at `closest_point(p)`.
template <class T>
concept Shape = requires(const T& shape, const Vec3d& p) {
  { shape.closest_point(p) } -> std::convertible_to<Vec3d>;
  { shape.signed_distance(p) } -> std::convertible_to<double>;
  { shape.normal(p) } -> std::convertible_to<Vec3d>;
};

/// Sphere of radius `radius` [m] centred at the origin.
struct Sphere {
  double radius = 0.04;

  /// Throws std::invalid_argument unless radius is finite and > 0.
  explicit Sphere(double r = 0.04) : radius(r) {
    if (!(r > 0) || !std::isfinite(r)) throw std::invalid_argument("Sphere: radius must be > 0");
  }
  double signed_distance(const Vec3d& p) const { return p.norm() - radius; }
  Vec3d normal(const Vec3d& p) const {
    const double n = p.norm();
    return n > 0 ? Vec3d(p / n) : Vec3d::UnitZ();
  }
  Vec3d closest_point(const Vec3d& p) const { return radius * normal(p); }
};

/// Capped cylinder along z, centred at the origin: radius and half height [m].
struct Cylinder {
  double radius = 0.03;
  double half_height = 0.05;

  /// Throws std::invalid_argument unless both sizes are finite and > 0.
  explicit Cylinder(double r = 0.03, double h = 0.05) : radius(r), half_height(h) {
    if (!(r > 0) || !(h > 0) || !std::isfinite(r) || !std::isfinite(h)) {
      throw std::invalid_argument("Cylinder: radius and half_height must be > 0");
    }
  }
  double signed_distance(const Vec3d& p) const {
    const double dr = std::hypot(p.x(), p.y()) - radius;
    const double dz = std::abs(p.z()) - half_height;
    const double out = std::hypot(std::max(dr, 0.0), std::max(dz, 0.0));
    return std::min(std::max(dr, dz), 0.0) + out;
  }
  Vec3d closest_point(const Vec3d& p) const {
    const double r = std::hypot(p.x(), p.y());
    const Vec3d radial = r > 0 ? Vec3d(p.x() / r, p.y() / r, 0) : Vec3d::UnitX();
    const double dr = r - radius;
    const double dz = std::abs(p.z()) - half_height;
    const double sz = p.z() >= 0 ? 1.0 : -1.0;
    if (dr <= 0 && dz <= 0) {  // inside: the nearer of side and cap
      if (dr >= dz) return Vec3d(radial.x() * radius, radial.y() * radius, p.z());
      return Vec3d(p.x(), p.y(), sz * half_height);
    }
    const double rc = std::min(r, radius);
    return Vec3d(radial.x() * rc, radial.y() * rc, std::clamp(p.z(), -half_height, half_height));
  }
  Vec3d normal(const Vec3d& p) const {
    const Vec3d c = closest_point(p);
    const double r = std::hypot(c.x(), c.y());
    const bool on_side = std::abs(r - radius) <= 1e-12 * radius;
    const bool on_cap = std::abs(std::abs(c.z()) - half_height) <= 1e-12 * half_height;
    const Vec3d side = r > 0 ? Vec3d(c.x() / r, c.y() / r, 0) : Vec3d::UnitX();
    const Vec3d cap(0, 0, c.z() >= 0 ? 1.0 : -1.0);
    if (on_side && on_cap) {  // on the rim: the direction from the rim towards p
      const Vec3d d = p - c;
      return d.norm() > 0 ? Vec3d(d.normalized()) : Vec3d((side + cap).normalized());
    }
    return on_cap ? cap : side;
  }
};

/// Axis-aligned box centred at the origin with the given half extents [m].
struct Box {
  Vec3d half_extents{0.04, 0.03, 0.02};

  /// Throws std::invalid_argument unless all half extents are finite and > 0.
  explicit Box(const Vec3d& h = Vec3d(0.04, 0.03, 0.02)) : half_extents(h) {
    if (!(h.array() > 0).all() || !h.allFinite()) {
      throw std::invalid_argument("Box: half extents must be > 0");
    }
  }
  double signed_distance(const Vec3d& p) const {
    const Vec3d d = p.cwiseAbs() - half_extents;
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
  }
  Vec3d closest_point(const Vec3d& p) const {
    const Vec3d d = p.cwiseAbs() - half_extents;
    if ((d.array() <= 0).all()) {  // inside: push to the nearest face
      Eigen::Index axis;
      d.maxCoeff(&axis);
      Vec3d c = p;
      c[axis] = p[axis] >= 0 ? half_extents[axis] : -half_extents[axis];
      return c;
    }
    return p.cwiseMax(-half_extents).cwiseMin(half_extents);
  }
  Vec3d normal(const Vec3d& p) const {
    const Vec3d c = closest_point(p);
    const Vec3d d = p - c;
    if (d.norm() > 1e-12 && signed_distance(p) > 0) return d.normalized();
    Eigen::Index axis;
    (c.cwiseAbs() - half_extents).maxCoeff(&axis);
    Vec3d n = Vec3d::Zero();
    n[axis] = c[axis] >= 0 ? 1.0 : -1.0;
    return n;
  }
};

}  // namespace taxel::sim
