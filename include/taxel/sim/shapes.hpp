// SPDX-License-Identifier: MIT
// Analytic shapes with exact closest point, signed distance and outward normal.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "taxel/core/deferred.hpp"
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
  double radius = 0.04;  ///< [m]

  /// Throws std::invalid_argument unless radius is finite and > 0.
  explicit Sphere(double r = 0.04) : radius(r) {
    if (!(r > 0) || !std::isfinite(r)) throw std::invalid_argument("Sphere: radius must be > 0");
  }
  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    return p.norm() - radius;
  }
  /// Unit outward normal of the surface at the point closest to `p`.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
    const double n = p.norm();
    return n > 0 ? Vec3d(p / n) : Vec3d::UnitZ();
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
    return radius * normal(p);
  }
};

/// Capped cylinder along z, centred at the origin: radius and half height [m].
struct Cylinder {
  double radius = 0.03;       ///< [m]
  double half_height = 0.05;  ///< Half the length along z, caps excluded [m].

  /// Throws std::invalid_argument unless both sizes are finite and > 0.
  explicit Cylinder(double r = 0.03, double h = 0.05) : radius(r), half_height(h) {
    if (!(r > 0) || !(h > 0) || !std::isfinite(r) || !std::isfinite(h)) {
      throw std::invalid_argument("Cylinder: radius and half_height must be > 0");
    }
  }
  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    const double dr = std::hypot(p.x(), p.y()) - radius;
    const double dz = std::abs(p.z()) - half_height;
    const double out = std::hypot(std::max(dr, 0.0), std::max(dz, 0.0));
    return std::min(std::max(dr, dz), 0.0) + out;
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
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
  /// Unit outward normal of the surface at the point closest to `p`.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
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
  /// Half the side lengths along x, y, z [m].
  Vec3d half_extents{0.04, 0.03, 0.02};

  /// Throws std::invalid_argument unless all half extents are finite and > 0.
  explicit Box(const Vec3d& h = Vec3d(0.04, 0.03, 0.02)) : half_extents(h) {
    if (!(h.array() > 0).all() || !h.allFinite()) {
      throw std::invalid_argument("Box: half extents must be > 0");
    }
  }
  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    const Vec3d d = p.cwiseAbs() - half_extents;
    return d.cwiseMax(0.0).norm() + std::min(d.maxCoeff(), 0.0);
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
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
  /// Unit outward normal of the surface at the point closest to `p`.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
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

/// Solid cone along z, centred at the origin: base disc of radius `radius` at z = -h/2, apex at
/// z = +h/2 (`height` = h) [m].
struct Cone {
  double radius = 0.03;  ///< [m]
  double height = 0.06;  ///< From the base (z = 0) to the apex [m].

  /// Throws std::invalid_argument unless both sizes are finite and > 0.
  explicit Cone(double r = 0.03, double h = 0.06) : radius(r), height(h) {
    if (!(r > 0) || !(h > 0) || !std::isfinite(r) || !std::isfinite(h)) {
      throw std::invalid_argument("Cone: radius and height must be > 0");
    }
  }
  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    const Section s = section(p);
    return s.inside ? -s.distance : s.distance;
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
    return lift(p, section(p).closest);
  }
  /// Unit outward normal of the surface at the point closest to `p`.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
    const Section s = section(p);
    Eigen::Vector2d n2;                           // outward normal in the (r, z) half-plane
    const Eigen::Vector2d slant(height, radius);  // normal of the slanted side, unnormalised
    if (s.feature == 0) {
      n2 = {0.0, -1.0};
    } else if (s.feature == 1) {
      n2 = slant.normalized();
    } else {  // the rim or the apex: towards the point, or the mean of the faces there
      const Eigen::Vector2d d = s.query - s.closest;
      n2 = d.norm() > 1e-15 && !s.inside
               ? Eigen::Vector2d(d.normalized())
               : Eigen::Vector2d((s.feature == 2 ? Eigen::Vector2d(0.0, -1.0) + slant.normalized()
                                                 : Eigen::Vector2d(0.0, 1.0))
                                     .normalized());
    }
    const double r = std::hypot(p.x(), p.y());
    const Vec3d radial = r > 0 ? Vec3d(p.x() / r, p.y() / r, 0) : Vec3d::UnitX();
    return (n2.x() * radial + Vec3d(0, 0, n2.y())).normalized();
  }

 private:
  struct Section {
    Eigen::Vector2d query;    // (r, z) of the point
    Eigen::Vector2d closest;  // on the section's boundary
    double distance = 0.0;
    bool inside = false;
    int feature = 0;  // 0 base, 1 slant, 2 rim, 3 apex
  };
  // The closest point of the triangle (0, -h/2), (R, -h/2), (0, h/2) boundary, without the
  // axis edge, to (r, z).
  template <class D = void>
  Section section(const Deferred<Vec3d, D>& p) const {
    Section s;
    s.query = {std::hypot(p.x(), p.y()), p.z()};
    const Eigen::Vector2d base0(0.0, -0.5 * height), rim(radius, -0.5 * height),
        apex(0.0, 0.5 * height);
    const auto on_segment = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b, double& t) {
      const Eigen::Vector2d ab = b - a;
      t = std::clamp((s.query - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      return Eigen::Vector2d(a + t * ab);
    };
    double tb = 0.0, ts = 0.0;
    const Eigen::Vector2d cb = on_segment(base0, rim, tb);
    const Eigen::Vector2d cs = on_segment(rim, apex, ts);
    const double db = (s.query - cb).norm(), ds = (s.query - cs).norm();
    if (db <= ds) {
      s.closest = cb;
      s.distance = db;
      s.feature = tb >= 1.0 ? 2 : 0;
    } else {
      s.closest = cs;
      s.distance = ds;
      s.feature = ts <= 0.0 ? 2 : ts >= 1.0 ? 3 : 1;
    }
    // Inside: above the base and below the slant line r / R + (z + h/2) / h <= 1.
    s.inside = s.query.y() > -0.5 * height &&
               s.query.x() / radius + (s.query.y() + 0.5 * height) / height < 1.0;
    return s;
  }
  template <class D = void>
  static Vec3d lift(const Deferred<Vec3d, D>& p, const Eigen::Vector2d& rz) {
    const double r = std::hypot(p.x(), p.y());
    const Vec3d radial = r > 0 ? Vec3d(p.x() / r, p.y() / r, 0) : Vec3d::UnitX();
    return rz.x() * radial + Vec3d(0, 0, rz.y());
  }
};

/// Ellipsoid centred at the origin with semi-axes `semi_axes` (a, b, c) along x, y, z [m]:
/// (x/a)^2 + (y/b)^2 + (z/c)^2 = 1. The closest point solves the Lagrange condition
/// x_i = e_i^2 y_i / (t + e_i^2) for the largest root t of
/// F(t) = sum_i (e_i y_i / (t + e_i^2))^2 - 1, which is convex and decreasing for
/// t > -min e_i^2; Newton's method from the left end of the bracket
/// [-e_min^2 + e_min |y_min|, |e o y| - e_min^2] converges monotonically (Eberly, "Distance
/// from a point to an ellipse, an ellipsoid, or a hyperellipsoid", Geometric Tools, 2013).
struct Ellipsoid {
  /// Along x, y, z [m].
  Vec3d semi_axes{0.05, 0.035, 0.025};

  /// Throws std::invalid_argument unless all semi-axes are finite and > 0.
  explicit Ellipsoid(const Vec3d& e = Vec3d(0.05, 0.035, 0.025)) : semi_axes(e) {
    if (!(e.array() > 0).all() || !e.allFinite()) {
      throw std::invalid_argument("Ellipsoid: semi-axes must be finite and > 0");
    }
  }
  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    const double d = (p - closest_point(p)).norm();
    return p.cwiseQuotient(semi_axes).squaredNorm() < 1.0 ? -d : d;
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
    const Vec3d& e = semi_axes;
    // Work in the first octant; a coordinate on a symmetry plane is nudged off it so that F has
    // its pole (the far branch of the inside case picks one of two mirror-image answers).
    const double tiny = 1e-9 * e.maxCoeff();
    Vec3d y = p.cwiseAbs();
    for (int i = 0; i < 3; ++i) y[i] = std::max(y[i], tiny);
    const Vec3d e2 = e.cwiseProduct(e);
    Eigen::Index k;
    const double emin2 = e2.minCoeff(&k);
    const auto F = [&](double t, double& dF) {
      double f = -1.0;
      dF = 0.0;
      for (int i = 0; i < 3; ++i) {
        const double r = e[i] * y[i] / (t + e2[i]);
        f += r * r;
        dF -= 2.0 * r * r / (t + e2[i]);
      }
      return f;
    };
    double t = -emin2 + e[k] * y[k];  // F(t) >= 0 here
    for (int it = 0; it < 100; ++it) {
      double dF = 0.0;
      const double f = F(t, dF);
      if (!(f > 0.0) || dF == 0.0) break;
      const double next = t - f / dF;
      if (!(next > t)) break;  // converged to machine precision
      t = next;
    }
    Vec3d x;
    for (int i = 0; i < 3; ++i) x[i] = e2[i] * y[i] / (t + e2[i]);
    // Project the last rounding onto the surface along the ray from the centre.
    x /= std::sqrt(x.cwiseQuotient(e).squaredNorm());
    for (int i = 0; i < 3; ++i) x[i] = std::copysign(x[i], p[i]);
    return x;
  }
  /// Unit outward normal of the surface at the point closest to `p`.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
    const Vec3d c = closest_point(p);
    return c.cwiseQuotient(semi_axes.cwiseProduct(semi_axes)).normalized();
  }
};

/// Torus around the z axis, centred at the origin: distance `major_radius` R from the axis to
/// the tube's centre circle, tube radius `minor_radius` r < R [m]. Closed-form closest point: the
/// nearest point of the centre circle, then r towards the query.
struct Torus {
  double major_radius = 0.04;   ///< From the centre to the middle of the tube [m].
  double minor_radius = 0.015;  ///< Radius of the tube [m].

  /// Throws std::invalid_argument unless 0 < minor_radius < major_radius, both finite.
  explicit Torus(double R = 0.04, double r = 0.015) : major_radius(R), minor_radius(r) {
    if (!(r > 0) || !(R > r) || !std::isfinite(R)) {
      throw std::invalid_argument(
          "Torus: radii must be finite with 0 < minor_radius < major_radius");
    }
  }
  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    return (p - centre(p)).norm() - minor_radius;
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
    return centre(p) + minor_radius * normal(p);
  }
  /// Unit outward normal of the surface at the point closest to `p`.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
    const Vec3d c = centre(p);
    const Vec3d d = p - c;
    const double n = d.norm();
    if (n > 0) return d / n;
    return Vec3d(c.x(), c.y(), 0).normalized();  // on the centre circle: outwards
  }

 private:
  // The nearest point of the tube's centre circle (any, on the axis).
  template <class D = void>
  Vec3d centre(const Deferred<Vec3d, D>& p) const {
    const double r = std::hypot(p.x(), p.y());
    const Vec3d radial = r > 0 ? Vec3d(p.x() / r, p.y() / r, 0) : Vec3d::UnitX();
    return major_radius * radial;
  }
};

/// A closed, consistently oriented triangle mesh (counter-clockwise seen from outside), e.g.
/// read from PLY. Exact closest point through a bounding-volume hierarchy of axis-aligned boxes
/// (built in O(n log n), binary, split at the median centroid of the longest axis, up to four
/// triangles per leaf; a query visits the nearer child first and skips boxes farther than the
/// best point so far): about log(triangles) work per query on well-shaped meshes, and the same
/// answer as a scan of every triangle (ties go to the lowest face index). The sign of the
/// distance comes from angle-weighted pseudo-normals (Baerentzen and Aanaes 2005), exact for
/// closed meshes.
class TriangleMesh {
 public:
  /// Three vertex indices, counter-clockwise seen from outside.
  using Triangle = std::array<std::uint32_t, 3>;

  /// Throws std::invalid_argument for no triangles, an index out of range, a non-finite vertex
  /// or a triangle of zero area.
  template <class = void>
  TriangleMesh(std::vector<Vec3d> vertices, std::vector<Triangle> triangles)
      : v_(std::move(vertices)), t_(std::move(triangles)) {
    if (t_.empty()) throw std::invalid_argument("TriangleMesh: no triangles");
    for (std::size_t i = 0; i < v_.size(); ++i) {
      if (!v_[i].allFinite()) {
        throw std::invalid_argument("TriangleMesh: vertex " + std::to_string(i) + " is not finite");
      }
    }
    vertex_normal_.assign(v_.size(), Vec3d::Zero());
    face_normal_.resize(t_.size());
    area_.resize(t_.size());
    for (std::size_t f = 0; f < t_.size(); ++f) {
      for (const auto i : t_[f]) {
        if (i >= v_.size()) {
          throw std::invalid_argument("TriangleMesh: triangle " + std::to_string(f) +
                                      " refers to vertex " + std::to_string(i) + " of " +
                                      std::to_string(v_.size()));
        }
      }
      const Vec3d& a = v_[t_[f][0]];
      const Vec3d& b = v_[t_[f][1]];
      const Vec3d& c = v_[t_[f][2]];
      const Vec3d cross = (b - a).cross(c - a);
      area_[f] = 0.5 * cross.norm();
      if (!(area_[f] > 0.0)) {
        throw std::invalid_argument("TriangleMesh: triangle " + std::to_string(f) + " has no area");
      }
      face_normal_[f] = cross.normalized();
      // Angle-weighted vertex pseudo-normals; edge pseudo-normals by edge key.
      for (int k = 0; k < 3; ++k) {
        const Vec3d& p = v_[t_[f][static_cast<std::size_t>(k)]];
        const Vec3d e1 = (v_[t_[f][static_cast<std::size_t>((k + 1) % 3)]] - p).normalized();
        const Vec3d e2 = (v_[t_[f][static_cast<std::size_t>((k + 2) % 3)]] - p).normalized();
        vertex_normal_[t_[f][static_cast<std::size_t>(k)]] +=
            std::acos(std::clamp(e1.dot(e2), -1.0, 1.0)) * face_normal_[f];
      }
    }
    edge_normal_.resize(t_.size());
    std::vector<std::pair<std::uint64_t, std::size_t>> edges;  // (key, face * 3 + k)
    edges.reserve(3 * t_.size());
    for (std::size_t f = 0; f < t_.size(); ++f) {
      for (std::size_t k = 0; k < 3; ++k)
        edges.emplace_back(edge_key(t_[f][k], t_[f][(k + 1) % 3]), f * 3 + k);
    }
    std::sort(edges.begin(), edges.end());
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i;
      Vec3d sum = Vec3d::Zero();
      while (j < edges.size() && edges[j].first == edges[i].first)
        sum += face_normal_[edges[j++].second / 3];
      for (std::size_t k = i; k < j; ++k)
        edge_normal_[edges[k].second / 3][edges[k].second % 3] = sum;
      i = j;
    }
    cumulative_area_.resize(t_.size());
    double total = 0.0;
    for (std::size_t f = 0; f < t_.size(); ++f) cumulative_area_[f] = total += area_[f];
    build_hierarchy();
  }

  /// The vertices [m].
  [[nodiscard]] const std::vector<Vec3d>& vertices() const noexcept { return v_; }
  /// The triangles.
  [[nodiscard]] const std::vector<Triangle>& triangles() const noexcept { return t_; }
  /// Area of triangle f [m^2].
  [[nodiscard]] double area(std::size_t f) const { return area_.at(f); }
  /// Unit normal of triangle f.
  [[nodiscard]] const Vec3d& face_normal(std::size_t f) const { return face_normal_.at(f); }
  /// Total area [m^2].
  [[nodiscard]] double surface_area() const noexcept { return cumulative_area_.back(); }
  /// The triangle holding area fraction u in [0, 1) of the surface, triangles in index order
  /// (binary search): u uniform gives area-uniform triangles.
  [[nodiscard]] std::size_t face_at(double u) const noexcept {
    const auto it = std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(),
                                     u * cumulative_area_.back());
    return std::min(static_cast<std::size_t>(it - cumulative_area_.begin()), t_.size() - 1);
  }
  /// Nodes in the bounding-volume hierarchy.
  [[nodiscard]] std::size_t hierarchy_nodes() const noexcept { return nodes_.size(); }

  /// Signed distance of `p` to the surface [m]: negative inside.
  template <class D = void>
  double signed_distance(const Deferred<Vec3d, D>& p) const {
    const Hit h = nearest(p);
    const double d = std::sqrt(h.d2);
    return (p - h.point).dot(h.pseudo_normal) < 0.0 ? -d : d;
  }
  /// The point of the surface closest to `p`.
  template <class D = void>
  Vec3d closest_point(const Deferred<Vec3d, D>& p) const {
    return nearest(p).point;
  }
  /// The face normal where the closest point lies inside a face; the pseudo-normal (or the
  /// direction to p) on edges and vertices.
  template <class D = void>
  Vec3d normal(const Deferred<Vec3d, D>& p) const {
    const Hit h = nearest(p);
    if (h.feature == 6) return face_normal_[h.face];
    const Vec3d d = p - h.point;
    const double sign = d.dot(h.pseudo_normal) < 0.0 ? -1.0 : 1.0;
    return d.norm() > 1e-12 ? Vec3d(sign * d.normalized()) : Vec3d(h.pseudo_normal.normalized());
  }

 private:
  struct Hit {
    Vec3d point = Vec3d::Zero();
    Vec3d pseudo_normal = Vec3d::UnitZ();
    double d2 = std::numeric_limits<double>::infinity();
    std::size_t face = 0;
    int feature = 6;  // 0-2 vertex k, 3-5 edge k (from vertex k to k+1), 6 face
  };

  static std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
    return a < b ? (std::uint64_t{a} << 32) | b : (std::uint64_t{b} << 32) | a;
  }

  // A node of the hierarchy: its box, and either a leaf's triangles (order_[first, first +
  // count)) or, with count == 0, an inner node whose children are nodes first - 1 and first.
  struct Node {
    Vec3d lo, hi;
    std::uint32_t first = 0;
    std::uint32_t count = 0;
  };
  static constexpr std::uint32_t kLeafSize = 4;

  [[nodiscard]] static double box_distance2(const Node& n, const Vec3d& p) noexcept {
    const Vec3d d = (n.lo - p).cwiseMax(p - n.hi).cwiseMax(0.0);
    return d.squaredNorm();
  }

  template <class = void>
  void build_hierarchy() {
    const std::size_t n = t_.size();
    if (n > std::size_t{0xffffffff} / 2)
      throw std::invalid_argument("TriangleMesh: too many triangles");
    std::vector<Vec3d> centroid(n);
    for (std::size_t f = 0; f < n; ++f)
      centroid[f] = (v_[t_[f][0]] + v_[t_[f][1]] + v_[t_[f][2]]) / 3.0;
    order_.resize(n);
    for (std::size_t f = 0; f < n; ++f) order_[f] = static_cast<std::uint32_t>(f);
    nodes_.clear();
    nodes_.reserve(2 * (n / kLeafSize + 1));
    // Depth-first with an explicit stack of (node, first, count); left children follow their
    // parent, right children are linked by index.
    struct Task {
      std::size_t node;
      std::uint32_t first, count;
    };
    std::vector<Task> todo{{0, 0, static_cast<std::uint32_t>(n)}};
    nodes_.emplace_back();
    while (!todo.empty()) {
      const Task task = todo.back();
      todo.pop_back();
      Vec3d lo = Vec3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
      Vec3d clo = lo, chi = hi;
      for (std::uint32_t i = task.first; i < task.first + task.count; ++i) {
        for (const auto vi : t_[order_[i]]) {
          lo = lo.cwiseMin(v_[vi]);
          hi = hi.cwiseMax(v_[vi]);
        }
        clo = clo.cwiseMin(centroid[order_[i]]);
        chi = chi.cwiseMax(centroid[order_[i]]);
      }
      nodes_[task.node].lo = lo;
      nodes_[task.node].hi = hi;
      if (task.count <= kLeafSize) {
        nodes_[task.node].first = task.first;
        nodes_[task.node].count = task.count;
        continue;
      }
      Eigen::Index axis = 0;
      (chi - clo).maxCoeff(&axis);
      const std::uint32_t half = task.count / 2;
      const auto begin = order_.begin() + task.first;
      std::nth_element(begin, begin + half, begin + task.count,
                       [&](std::uint32_t a, std::uint32_t b) {
                         return centroid[a][axis] < centroid[b][axis] ||
                                (centroid[a][axis] == centroid[b][axis] && a < b);
                       });
      const std::size_t left = nodes_.size();
      nodes_.emplace_back();
      const std::size_t right = nodes_.size();
      nodes_.emplace_back();
      // Children are laid out as created; `first` of an inner node names its right child.
      nodes_[task.node].first = static_cast<std::uint32_t>(right);
      nodes_[task.node].count = 0;
      todo.push_back({right, task.first + half, task.count - half});
      todo.push_back({left, task.first, half});
    }
  }

  template <class D = void>
  Hit nearest(const Deferred<Vec3d, D>& p) const {
    Hit best;
    std::uint32_t stack[96];  // depth <= log2(triangles) + 1: median splits
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
      const Node& node = nodes_[stack[--top]];
      if (box_distance2(node, p) > best.d2) continue;
      if (node.count > 0) {
        for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
          const std::size_t f = order_[i];
          int feature = 6;
          const Vec3d c = closest_on_triangle(p, v_[t_[f][0]], v_[t_[f][1]], v_[t_[f][2]], feature);
          const double d2 = (p - c).squaredNorm();
          if (d2 < best.d2 || (d2 == best.d2 && f < best.face)) {
            best.d2 = d2;
            best.point = c;
            best.face = f;
            best.feature = feature;
          }
        }
        continue;
      }
      const std::uint32_t right = node.first;
      const std::uint32_t left = right - 1;
      const double dl = box_distance2(nodes_[left], p);
      const double dr = box_distance2(nodes_[right], p);
      if (top + 2 > 96) throw std::logic_error("TriangleMesh: hierarchy too deep");
      if (dl <= dr) {  // the nearer child on top
        stack[top++] = right;
        stack[top++] = left;
      } else {
        stack[top++] = left;
        stack[top++] = right;
      }
    }
    const auto& tri = t_[best.face];
    best.pseudo_normal =
        best.feature < 3   ? vertex_normal_[tri[static_cast<std::size_t>(best.feature)]]
        : best.feature < 6 ? edge_normal_[best.face][static_cast<std::size_t>(best.feature - 3)]
                           : face_normal_[best.face];
    return best;
  }

  // Closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5), with
  // the feature it lies on.
  template <class D = void>
  static Vec3d closest_on_triangle(const Deferred<Vec3d, D>& p, const Vec3d& a, const Vec3d& b,
                                   const Vec3d& c, int& feature) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = ab.dot(ap), d2 = ac.dot(ap);
    if (d1 <= 0 && d2 <= 0) return feature = 0, a;
    const Vec3d bp = p - b;
    const double d3 = ab.dot(bp), d4 = ac.dot(bp);
    if (d3 >= 0 && d4 <= d3) return feature = 1, b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return feature = 3, Vec3d(a + (d1 / (d1 - d3)) * ab);
    const Vec3d cp = p - c;
    const double d5 = ab.dot(cp), d6 = ac.dot(cp);
    if (d6 >= 0 && d5 <= d6) return feature = 2, c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return feature = 5, Vec3d(a + (d2 / (d2 - d6)) * ac);
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
      return feature = 4, Vec3d(b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b));
    }
    const double denom = 1.0 / (va + vb + vc);
    feature = 6;
    return a + ab * (vb * denom) + ac * (vc * denom);
  }

  std::vector<Vec3d> v_;
  std::vector<Triangle> t_;
  std::vector<Vec3d> face_normal_;
  std::vector<double> area_;
  std::vector<Vec3d> vertex_normal_;
  std::vector<std::array<Vec3d, 3>> edge_normal_;  // per face, edge k from vertex k to k + 1
  std::vector<double> cumulative_area_;            // area of faces 0..f
  std::vector<Node> nodes_;                        // the hierarchy, root first
  std::vector<std::uint32_t> order_;               // triangles in leaf order
};

/// The box as a mesh of 12 triangles (two per face), outward oriented.
template <class = void>
inline TriangleMesh box_mesh(const Box& box) {
  std::vector<Vec3d> v;
  for (int i = 0; i < 8; ++i) {
    v.emplace_back((i & 1 ? 1.0 : -1.0) * box.half_extents.x(),
                   (i & 2 ? 1.0 : -1.0) * box.half_extents.y(),
                   (i & 4 ? 1.0 : -1.0) * box.half_extents.z());
  }
  // Each face as a quad a b c d, counter-clockwise seen from outside.
  const std::uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                     {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<TriangleMesh::Triangle> t;
  for (const auto& q : quads) {
    t.push_back({q[0], q[1], q[2]});
    t.push_back({q[0], q[2], q[3]});
  }
  return TriangleMesh(std::move(v), std::move(t));
}

/// The capped cylinder as a mesh: `segments` facets around (>= 3), fans on the caps about their
/// centres; outward oriented. Its facets lie inside the true surface by at most
/// radius (1 - cos(pi / segments)).
template <class = void>
inline TriangleMesh cylinder_mesh(const Cylinder& cyl, int segments) {
  if (segments < 3 || segments > (1 << 20)) {
    throw std::invalid_argument("cylinder_mesh: segments must be in [3, 2^20]");
  }
  const auto n = static_cast<std::uint32_t>(segments);
  std::vector<Vec3d> v;
  for (std::uint32_t i = 0; i < n; ++i) {
    const double a = 2.0 * std::numbers::pi * i / n;
    v.emplace_back(cyl.radius * std::cos(a), cyl.radius * std::sin(a), -cyl.half_height);
    v.emplace_back(cyl.radius * std::cos(a), cyl.radius * std::sin(a), cyl.half_height);
  }
  const std::uint32_t bottom = 2 * n, top = 2 * n + 1;
  v.emplace_back(0.0, 0.0, -cyl.half_height);
  v.emplace_back(0.0, 0.0, cyl.half_height);
  std::vector<TriangleMesh::Triangle> t;
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    t.push_back({2 * i, 2 * j, 2 * j + 1});  // side
    t.push_back({2 * i, 2 * j + 1, 2 * i + 1});
    t.push_back({bottom, 2 * j, 2 * i});  // caps
    t.push_back({top, 2 * i + 1, 2 * j + 1});
  }
  return TriangleMesh(std::move(v), std::move(t));
}

/// A sphere of radius r tessellated as an icosphere: the icosahedron, each triangle split in
/// four `subdivisions` times, vertices pushed onto the sphere (20 * 4^s triangles).
template <class = void>
inline TriangleMesh icosphere(double r, int subdivisions) {
  if (!(r > 0) || subdivisions < 0 || subdivisions > 7) {
    throw std::invalid_argument("icosphere: r must be > 0 and subdivisions in [0, 7]");
  }
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3d> v{{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                       {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  std::vector<TriangleMesh::Triangle> t{
      {0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
      {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
      {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int s = 0; s < subdivisions; ++s) {
    std::vector<std::pair<std::uint64_t, std::uint32_t>> mids;
    const auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const std::uint64_t key = a < b ? (std::uint64_t{a} << 32) | b : (std::uint64_t{b} << 32) | a;
      for (const auto& [k, i] : mids) {
        if (k == key) return i;
      }
      v.push_back((v[a] + v[b]).normalized());
      mids.emplace_back(key, static_cast<std::uint32_t>(v.size() - 1));
      return mids.back().second;
    };
    std::vector<TriangleMesh::Triangle> next;
    next.reserve(t.size() * 4);
    for (const auto& tri : t) {
      const std::uint32_t ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]),
                          ca = mid(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    t = std::move(next);
  }
  for (auto& p : v) p *= r;
  return TriangleMesh(std::move(v), std::move(t));
}

}  // namespace taxel::sim
