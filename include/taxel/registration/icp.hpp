// SPDX-License-Identifier: MIT
// Iterative closest point over a preprocessed Target, composed at compile time from an error
// policy (PointToPoint: closed-form weighted Kabsch/Umeyama with the reflection fix;
// PointToPlane: Gauss-Newton on a 6-D twist) and a robust kernel, with correspondence
// rejection by distance and by trimming. The Icp object is a workspace: after the first
// alignment of a source of a given size, iterations allocate nothing.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/core/status.hpp"
#include "taxel/registration/kernels.hpp"
#include "taxel/registration/target.hpp"

namespace taxel::registration {

using Mat6d = Eigen::Matrix<double, 6, 6>;
using Vec6d = Eigen::Matrix<double, 6, 1>;

namespace detail {
/// Eigenvalues (ascending) and orthonormal eigenvectors (the matching columns) of a symmetric
/// 6x6 matrix, by cyclic Jacobi rotations (Golub and Van Loan, Matrix Computations, 4th ed.,
/// Sec. 8.5.2) until the off-diagonal part is below double rounding of the whole. Written out
/// instead of Eigen::SelfAdjointEigenSolver<Mat6d>, whose Householder tridiagonalisation cost
/// every translation unit that aligns point-to-plane about 18 s of compile time (GCC 12, -O3);
/// Jacobi is at least as accurate (for positive definite matrices it finds even the small
/// eigenvalues to high relative accuracy: Demmel and Veselic, SIAM J. Matrix Anal. Appl. 13(4),
/// 1992). A matrix with a NaN or infinite entry (or one whose squared norm overflows) gives
/// NaN eigenvalues. (A template only so that its body is compiled where it is called, like the
/// solvers that call it.)
template <class D = void>
void symmetric_eigen(Deferred<Mat6d, D> a, Deferred<Vec6d, D>& values,
                     Deferred<Mat6d, D>& vectors) {
  vectors.setIdentity();
  const double whole = a.squaredNorm();
  if (!std::isfinite(whole)) {
    values.setConstant(std::numeric_limits<double>::quiet_NaN());
    return;
  }
  constexpr double kEps2 =
      std::numeric_limits<double>::epsilon() * std::numeric_limits<double>::epsilon();
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0.0;
    for (int p = 0; p < 6; ++p) {
      for (int q = p + 1; q < 6; ++q) off += a(p, q) * a(p, q);
    }
    if (!(off > kEps2 * whole)) break;
    for (int p = 0; p < 6; ++p) {
      for (int q = p + 1; q < 6; ++q) {
        const double apq = a(p, q);
        if (apq == 0.0) continue;
        // The rotation that zeroes a(p, q): t = tan of its angle, the smaller root.
        const double theta = (a(q, q) - a(p, p)) / (2.0 * apq);
        const double t =
            (theta >= 0.0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), sn = t * c;
        for (int k = 0; k < 6; ++k) {  // a <- a J
          const double kp = a(k, p), kq = a(k, q);
          a(k, p) = c * kp - sn * kq;
          a(k, q) = sn * kp + c * kq;
        }
        for (int k = 0; k < 6; ++k) {  // a <- J' a
          const double pk = a(p, k), qk = a(q, k);
          a(p, k) = c * pk - sn * qk;
          a(q, k) = sn * pk + c * qk;
        }
        a(p, q) = a(q, p) = 0.0;       // what the rotation is for; leave no rounding there
        for (int k = 0; k < 6; ++k) {  // vectors <- vectors J
          const double kp = vectors(k, p), kq = vectors(k, q);
          vectors(k, p) = c * kp - sn * kq;
          vectors(k, q) = sn * kp + c * kq;
        }
      }
    }
  }
  values = a.diagonal();
  for (int i = 1; i < 6; ++i) {  // insertion sort, ascending, the vectors alongside
    for (int j = i; j > 0 && values(j) < values(j - 1); --j) {
      std::swap(values(j), values(j - 1));
      vectors.col(j).swap(vectors.col(j - 1));
    }
  }
}
}  // namespace detail

/// Options of Icp. Distances in metres, angles in radians.
struct IcpConfig {
  int max_iterations = 50;  ///< >= 1
  /// Correspondences farther apart than this are rejected (> 0; infinity keeps all).
  double max_distance = std::numeric_limits<double>::infinity();
  /// After the distance gate, drop this fraction of the worst correspondences, [0, 1).
  double trim_fraction = 0.0;
  double translation_tolerance = 1e-6;  ///< converged when an update moves less than this...
  double rotation_tolerance = 1e-6;     ///< ...and turns less than this
  /// Also converged when the RMSE changes by less than this fraction of itself (0: off).
  double relative_error_tolerance = 0.0;
  /// Fewest correspondences to solve with; 0 means the error policy's minimum (3 or 6).
  std::size_t min_correspondences = 0;
  /// Take correspondences from the target's closest-point field where it has one (a single
  /// lookup, off by up to half a field cell diagonal) and search exactly elsewhere. For coarse
  /// stages; the final iterations of an accurate alignment should be exact.
  bool approximate = false;
  /// When > 0 and the source has at least twice as many points: first align an evenly spaced
  /// subsample of this many points (on the target's closest-point field when it has one, with
  /// tolerances ten times looser), then the whole source, exactly, from there. Iterations
  /// count both stages. 0: off.
  std::size_t coarse_points = 0;
  /// Keep a source point's exact match without searching while the point has moved, since the
  /// search that found it, less than half the gap between that match's distance and every
  /// other target point's (index::UniformGrid::nearest_stable): the same correspondences,
  /// found by fewer searches once the updates become small. Off only to time the searches.
  bool keep_stable_matches = true;
};

/// The outcome of one alignment. `ok`: converged (the update fell below the tolerances, the
/// RMSE change below relative_error_tolerance, or the iteration returned to the pose it left
/// one update before, a two-cycle between two sets of correspondences, which point-to-plane
/// can enter on sparse clouds: then the pose of the two with the lower RMSE); `not_converged`:
/// the iteration cap was hit
/// (the last iterate is returned); `degenerate`: the geometry does not fix the pose (too few
/// points or correspondences, collinear points, or for point-to-plane a plane, sphere or
/// cylinder patch); transform and RMSE are still those of the last iterate, never NaN;
/// `invalid_input`: a bad initial transform.
struct IcpResult : Outcome {
  Isometry3d transform = Isometry3d::Identity();  ///< T_target_source
  double rmse = 0.0;             ///< RMS Euclidean distance of the inlier pairs [m]
  double inlier_fraction = 0.0;  ///< inliers / finite source points
  std::size_t inliers = 0;       ///< pairs kept by the distance gate and trimming
  std::size_t skipped = 0;       ///< non-finite source points, ignored
  int iterations = 0;            ///< updates applied
  /// Sum of J'J over the inlier pairs at the final pose, twist order (rotation, translation)
  /// about the target frame's origin, unit weights: divide by the residual variance for the
  /// Fisher information of the pose.
  Mat6d information = Mat6d::Zero();
};

/// One source-target pair of an iteration.
struct Correspondence {
  Vec3d p;                ///< source point under the current transform
  Vec3d q;                ///< its nearest target point
  Vec3d n;                ///< the target normal at q
  double d2 = 0.0;        ///< |p - q|^2
  double residual = 0.0;  ///< the error policy's residual magnitude
  double weight = 1.0;    ///< the kernel's weight
};

/// Minimises sum w |p - q|^2: closed form (weighted Kabsch with the reflection fix).
struct PointToPoint {
  static constexpr std::string_view name = "point-to-point";  ///< Name in messages.
  static constexpr std::size_t min_correspondences = 3;       ///< Fewest pairs a step needs.

  /// Residual of a pair [m] (for the kernel and the RMSE).
  [[nodiscard]] static double residual(const Correspondence& c) noexcept { return std::sqrt(c.d2); }

  /// The update `delta` (applied on the left) minimising the weighted error, or `degenerate`
  /// when the source points are collinear. (A template only so that the Eigen solvers it uses
  /// are compiled by the translation units that call it, not by every one that includes ICP.)
  template <class D = void>
  static Outcome solve(std::span<const Deferred<Correspondence, D>> cs, Isometry3d& delta) {
    double wsum = 0.0;
    Vec3d pm = Vec3d::Zero(), qm = Vec3d::Zero();
    for (const auto& c : cs) {
      wsum += c.weight;
      pm += c.weight * c.p;
      qm += c.weight * c.q;
    }
    if (!(wsum > 0.0)) return {Status::degenerate, "every correspondence has zero weight"};
    pm /= wsum;
    qm /= wsum;
    Mat3d h = Mat3d::Zero(), spread = Mat3d::Zero(), target_spread = Mat3d::Zero();
    for (const auto& c : cs) {
      const Vec3d dp = c.p - pm;
      const Vec3d dq = c.q - qm;
      h += c.weight * dp * dq.transpose();
      spread += c.weight * dp * dp.transpose();
      target_spread += c.weight * dq * dq.transpose();
    }
    // Both ends must span a plane: collinear (or coincident) points on either side leave the
    // rotation about their line free.
    const Eigen::SelfAdjointEigenSolver<Mat3d> eig(spread, Eigen::EigenvaluesOnly);
    if (!(eig.eigenvalues()(1) > 1e-12 * eig.eigenvalues()(2))) {
      return {Status::degenerate,
              "the source points are collinear: the rotation about their "
              "line is not determined"};
    }
    const Eigen::SelfAdjointEigenSolver<Mat3d> teig(target_spread, Eigen::EigenvaluesOnly);
    if (!(teig.eigenvalues()(1) > 1e-12 * teig.eigenvalues()(2))) {
      return {Status::degenerate,
              "the matched target points are collinear or fewer than three: the rotation "
              "about their line is not determined"};
    }
    const Eigen::JacobiSVD<Mat3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Mat3d d = Mat3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
    const Mat3d r = svd.matrixV() * d * svd.matrixU().transpose();
    delta.setIdentity();
    delta.linear() = r;
    delta.translation() = qm - r * pm;
    return {};
  }

  /// Adds J'J of the 3-D residual p - q (J = [-[p]x, I]).
  template <class D = void>
  static void add_information(const Deferred<Correspondence, D>& c, Mat6d& info) {
    Eigen::Matrix<double, 3, 6> j;
    j.leftCols<3>() << 0.0, c.p.z(), -c.p.y(), -c.p.z(), 0.0, c.p.x(), c.p.y(), -c.p.x(), 0.0;
    j.rightCols<3>().setIdentity();
    info.noalias() += j.transpose() * j;
  }
};

/// Minimises sum w (n . (p - q))^2 by Gauss-Newton on a twist about the source centroid,
/// J'J accumulated in closed form. Directions the target's geometry leaves free (eigenvalues of
/// J'J at the target points, rotations scaled by the source's RMS radius, below 1e-6 of the
/// largest) are not moved and make the result `degenerate`.
struct PointToPlane {
  static constexpr std::string_view name = "point-to-plane";  ///< Name in messages.
  static constexpr std::size_t min_correspondences = 6;       ///< Fewest pairs a step needs.
  static constexpr double kFreeDirection =
      1e-6;  ///< Eigenvalues of J'J below this share of the largest leave a direction free.

  /// Residual of a pair [m] (for the kernel and the RMSE).
  template <class D = void>
  [[nodiscard]] static double residual(const Deferred<Correspondence, D>& c) noexcept {
    return std::fabs(c.n.dot(c.p - c.q));
  }

  /// The Gauss-Newton update (a template only to defer compiling its Eigen solvers).
  template <class D = void>
  static Outcome solve(std::span<const Deferred<Correspondence, D>> cs, Isometry3d& delta) {
    double wsum = 0.0;
    Vec3d centre = Vec3d::Zero();
    for (const auto& c : cs) {
      wsum += c.weight;
      centre += c.weight * c.p;
    }
    if (!(wsum > 0.0)) return {Status::degenerate, "every correspondence has zero weight"};
    centre /= wsum;
    double spread = 0.0;
    for (const auto& c : cs) spread += c.weight * (c.p - centre).squaredNorm();
    // Rotations scaled by the source's RMS radius so both blocks are in metres.
    const double len = std::max(std::sqrt(spread / wsum), 1e-12);
    // h, g: the Gauss-Newton system at the source points. hq: the same at the target points,
    // whose null space is exactly the motions the target's shape leaves free (a plane's
    // in-plane slides and spin, a sphere's rotations about its centre, a cylinder's axis), so
    // degeneracy is decided on hq and the step is taken in the directions it constrains.
    // Lower triangles only, in plain arrays (a third of the products of full outer ones).
    // The two systems side by side, entry k of h at [2k] and of hq at [2k + 1] (and the two
    // Jacobians likewise), so each product pair is one two-wide vector operation.
    alignas(16) std::array<double, 42> hh{};
    std::array<double, 6> g6{};
    const double inv_len = 1.0 / len;
    for (const auto& c : cs) {
      const Vec3d a = (c.p - centre).cross(c.n) * inv_len;
      const Vec3d b = (c.q - centre).cross(c.n) * inv_len;
      alignas(16) const std::array<double, 12> jj = {a.x(),   b.x(),   a.y(),   b.y(),
                                                     a.z(),   b.z(),   c.n.x(), c.n.x(),
                                                     c.n.y(), c.n.y(), c.n.z(), c.n.z()};
      const double w = c.weight;
      const double wr = w * c.n.dot(c.p - c.q);
      std::size_t k = 0;
      for (std::size_t u = 0; u < 6; ++u) {
        const double wj0 = w * jj[2 * u], wj1 = w * jj[2 * u + 1];
        g6[u] += wr * jj[2 * u];
        for (std::size_t v = 0; v <= u; ++v, ++k) {
          hh[2 * k] += wj0 * jj[2 * v];
          hh[2 * k + 1] += wj1 * jj[2 * v + 1];
        }
      }
    }
    Mat6d h, hq;
    Vec6d g;
    for (std::size_t u = 0, k = 0; u < 6; ++u) {
      g(static_cast<Eigen::Index>(u)) = g6[u];
      for (std::size_t v = 0; v <= u; ++v, ++k) {
        const auto iu = static_cast<Eigen::Index>(u), iv = static_cast<Eigen::Index>(v);
        h(iu, iv) = h(iv, iu) = hh[2 * k];
        hq(iu, iv) = hq(iv, iu) = hh[2 * k + 1];
      }
    }
    Vec6d lambda;
    Mat6d basis;
    detail::symmetric_eigen(hq, lambda, basis);
    const double top = lambda(5);
    if (!(top > 0.0)) return {Status::degenerate, "the normals constrain no direction"};
    int free = 0;
    while (free < 6 && lambda(free) <= kFreeDirection * top) ++free;
    Vec6d x;
    if (free == 0) {
      x = -h.ldlt().solve(g);
    } else {
      // Newton step within the constrained subspace N (the eigenvectors past the free ones):
      // x = -N (N'hN)^-1 N'g. In the eigenbasis that is the 6x6 system whose free rows and
      // columns are the identity's and whose free right-hand entries are zero, so the
      // fixed-size solver of the full step serves here too (the dynamic-size products and
      // LDLT this took before were much of the compile time of every caller).
      Mat6d reduced = basis.transpose() * h * basis;
      Vec6d rhs = basis.transpose() * g;
      for (int k = 0; k < free; ++k) {
        reduced.row(k).setZero();
        reduced.col(k).setZero();
        reduced(k, k) = 1.0;
        rhs(k) = 0.0;
      }
      x = -basis * reduced.ldlt().solve(rhs);
    }
    const Vec3d omega = x.template head<3>() / len;
    const Vec3d v = x.template tail<3>();
    const double angle = omega.norm();
    const Mat3d r = angle > 0.0 ? Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix()
                                : Mat3d::Identity();
    delta.setIdentity();
    delta.linear() = r;
    delta.translation() = centre + v - r * centre;
    if (free > 0) {
      return {Status::degenerate,
              std::to_string(free) +
                  " of 6 pose directions are not constrained by the target's normals "
                  "(a plane, sphere or cylinder patch): the pose is one of many equally good "
                  "fits"};
    }
    return {};
  }

  /// Adds J'J of the scalar residual n . (p - q) (J = [p x n, n]).
  template <class D = void>
  static void add_information(const Deferred<Correspondence, D>& c, Mat6d& info) {
    Vec6d j;
    j.template head<3>() = c.p.cross(c.n);
    j.template tail<3>() = c.n;
    info.selfadjointView<Eigen::Lower>().rankUpdate(j);
  }
};

/// An ICP error policy.
template <class E>
concept IcpError = requires(const Correspondence& c, std::span<const Correspondence> cs,
                            Isometry3d& t, Mat6d& m) {
  { E::residual(c) } -> std::convertible_to<double>;
  { E::solve(cs, t) } -> std::convertible_to<Outcome>;
  E::add_information(c, m);
  { E::min_correspondences } -> std::convertible_to<std::size_t>;
};

/// ICP. `align` may be called any number of times, on any targets; not thread-safe (one Icp
/// per thread), while Targets may be shared.
template <IcpError Error = PointToPlane, RobustKernel Kernel = NoKernel>
class Icp {
 public:
  /// Throws std::invalid_argument naming the first bad field.
  explicit Icp(IcpConfig cfg = {}, Kernel kernel = {}) : cfg_(cfg), kernel_(kernel) {
    const auto bad = [](const std::string& what) {
      throw std::invalid_argument("IcpConfig::" + what);
    };
    if (cfg.max_iterations < 1) bad("max_iterations must be >= 1");
    if (!(cfg.max_distance > 0.0)) bad("max_distance must be > 0");
    if (!(cfg.trim_fraction >= 0.0 && cfg.trim_fraction < 1.0))
      bad("trim_fraction must be in [0, 1)");
    if (!(cfg.translation_tolerance >= 0.0) || !(cfg.rotation_tolerance >= 0.0) ||
        !(cfg.relative_error_tolerance >= 0.0)) {
      bad("tolerances must be >= 0");
    }
  }

  /// Aligns `source` to `target` from `initial` (T_target_source).
  template <Scalar S>
  IcpResult align(const Target<S>& target, std::span<const Vec3<S>> source,
                  const Isometry3d& initial = Isometry3d::Identity()) {
    IcpResult res;
    res.transform = initial;
    if (!initial.matrix().allFinite() ||
        !(initial.linear() * initial.linear().transpose()).isIdentity(1e-6) ||
        !(initial.linear().determinant() > 0.0)) {
      res.status = Status::invalid_input;
      res.message = "the initial transform is not a finite rotation and translation";
      res.transform.setIdentity();
      return res;
    }
    src_.clear();
    src_.reserve(source.size());
    for (const auto& p : source) {
      if (p.allFinite()) {
        src_.push_back(p.template cast<double>());
      } else {
        ++res.skipped;
      }
    }
    const std::size_t need = std::max<std::size_t>(
        cfg_.min_correspondences == 0 ? Error::min_correspondences : cfg_.min_correspondences,
        Error::min_correspondences);
    if (src_.size() < need) {
      res.status = Status::degenerate;
      res.message = std::to_string(src_.size()) + " finite source points; " +
                    std::string(Error::name) + " needs at least " + std::to_string(need);
      return res;
    }
    pairs_.reserve(src_.size());
    scratch_.reserve(src_.size());

    Isometry3d t = initial;
    int iterations = 0;
    // Coarse stage: an evenly spaced subsample, on the closest-point field when the target has
    // one, with tolerances ten times looser; its result starts the full alignment.
    if (cfg_.coarse_points > 0 && src_.size() >= 2 * cfg_.coarse_points &&
        cfg_.coarse_points >= need) {
      coarse_.clear();
      for (std::size_t i = 0; i < cfg_.coarse_points; ++i) {
        coarse_.push_back(src_[i * src_.size() / cfg_.coarse_points]);
      }
      active_ = &coarse_;
      approximate_ = cfg_.approximate || target.has_field();
      (void)iterate(target, t, need, 10.0, iterations);
    }
    active_ = &src_;
    approximate_ = cfg_.approximate;
    const Outcome end = iterate(target, t, need, 1.0, iterations);
    res.iterations = iterations;
    return finish(res, target, t, end.status, end.message);
  }

  /// Aligns the points of `source`.
  template <Scalar S>
  IcpResult align(const Target<S>& target, const PointCloud<S>& source,
                  const Isometry3d& initial = Isometry3d::Identity()) {
    return align(target, std::span<const Vec3<S>>(source.points), initial);
  }

  /// The configuration.
  [[nodiscard]] const IcpConfig& config() const noexcept { return cfg_; }
  /// The robust kernel.
  [[nodiscard]] const Kernel& kernel() const noexcept { return kernel_; }

 private:
  // Iterates from t (updated in place) on *active_ until converged (ok), the cap
  // (not_converged) or too few pairs (degenerate); a degenerate last solve makes the result
  // degenerate. `iterations` counts the updates applied.
  template <Scalar S>
  Outcome iterate(const Target<S>& target, Isometry3d& t, std::size_t need, double loosen,
                  int& iterations) {
    double previous_rmse = std::numeric_limits<double>::infinity();
    // The pose the previous update started from, and its RMSE (infinite before the first).
    Isometry3d back = t;
    double back_rmse = previous_rmse;
    Outcome last{};
    matches_.assign(active_->size(), Match{});  // a new stage: no previous matches
    for (int it = 0; it < cfg_.max_iterations; ++it) {
      const double rmse = correspond(target, t);
      if (pairs_.size() < need) {
        return {Status::degenerate,
                std::to_string(pairs_.size()) + " correspondences within max_distance; " +
                    std::string(Error::name) + " needs at least " + std::to_string(need)};
      }
      if (cfg_.relative_error_tolerance > 0.0 &&
          std::fabs(previous_rmse - rmse) <= loosen * cfg_.relative_error_tolerance * rmse) {
        return last;
      }
      previous_rmse = rmse;
      Isometry3d delta = Isometry3d::Identity();
      last = Error::solve(pairs_, delta);
      if (last.status == Status::degenerate && Error::min_correspondences == 3) {
        return last;  // nothing to apply
      }
      if (!delta.matrix().allFinite()) return {Status::degenerate, "the update is not finite"};
      const Isometry3d from = t;
      t = delta * t;
      // Re-orthonormalise against drift over many updates.
      t.linear() = Eigen::Quaterniond(t.linear()).normalized().toRotationMatrix();
      ++iterations;
      const double angle = Eigen::AngleAxisd(delta.linear()).angle();
      if (delta.translation().norm() <= loosen * cfg_.translation_tolerance &&
          angle <= loosen * cfg_.rotation_tolerance) {
        return last;
      }
      // Back where the previous update started: the next updates would alternate between the
      // same two poses until the cap. Keep the better of the two.
      if (back_rmse < std::numeric_limits<double>::infinity()) {
        const Isometry3d gap = t * back.inverse();
        if (gap.translation().norm() <= loosen * cfg_.translation_tolerance &&
            Eigen::AngleAxisd(gap.linear()).angle() <= loosen * cfg_.rotation_tolerance) {
          t = back_rmse < rmse ? back : from;
          return last;
        }
      }
      back = from;
      back_rmse = rmse;
    }
    if (last.status == Status::degenerate) return last;
    return {Status::not_converged,
            "reached max_iterations = " + std::to_string(cfg_.max_iterations) +
                " before the update fell below the tolerances"};
  }

  // Fills pairs_ at transform t (gate, trimming, kernel weights); returns the inlier RMSE.
  template <Scalar S>
  double correspond(const Target<S>& target, const Isometry3d& t) {
    pairs_.clear();
    const auto& pts = target.points();
    const auto& nrm = target.normals();
    const S gate = static_cast<S>(std::min(cfg_.max_distance, 1e300));
    const double gate2 = cfg_.max_distance * cfg_.max_distance;
    for (std::size_t i = 0; i < active_->size(); ++i) {
      const Vec3d p = t * (*active_)[i];
      const Vec3<S> ps = p.template cast<S>();
      index::PointId id = 0;
      if (const auto approx = approximate_ ? target.field_nearest(ps) : std::nullopt) {
        id = *approx;
      } else if (Match& m = matches_[i]; m.id != kNoHint && (p - m.at).squaredNorm() < m.radius2) {
        // Moved less than the stable radius of its last search: that match is still the
        // nearest, within the gate exactly when the search would find it there.
        id = m.id;
        if (!(index::squared_distance(pts[id], ps) <= gate * gate)) {
          m = Match{};
          continue;
        }
      } else {
        // Exact, searched from the point's previous match: after a small update the match
        // moves little, so the ball it bounds holds few cells (the same answer as without).
        std::optional<index::Neighbor<S>> nb;
        double radius = 0.0;
        if (m.id == kNoHint) {
          nb = target.nearest_within(ps, gate);
        } else if (!cfg_.keep_stable_matches) {
          nb = target.nearest_within(ps, gate, m.id);
        } else if (const auto st = target.nearest_stable(ps, gate, m.id)) {
          nb = st->nearest;
          radius = st->radius;
        }
        if (!nb) {
          m = Match{};
          continue;
        }
        id = nb->id;
        m = Match{id, p, radius * radius};
      }
      Correspondence c;
      c.p = p;
      c.q = pts[id].template cast<double>();
      c.n = nrm[id].template cast<double>();
      c.d2 = (c.p - c.q).squaredNorm();
      if (c.d2 > gate2) continue;
      pairs_.push_back(c);
    }
    if (cfg_.trim_fraction > 0.0 && pairs_.size() > 1) {
      const auto keep = static_cast<std::size_t>(
          std::ceil((1.0 - cfg_.trim_fraction) * static_cast<double>(pairs_.size())));
      if (keep < pairs_.size()) {
        scratch_.clear();
        for (const auto& c : pairs_) scratch_.push_back(c.d2);
        std::nth_element(scratch_.begin(), scratch_.begin() + static_cast<std::ptrdiff_t>(keep - 1),
                         scratch_.end());
        const double limit = scratch_[keep - 1];
        std::erase_if(pairs_, [limit](const Correspondence& c) { return c.d2 > limit; });
      }
    }
    double sum = 0.0;
    for (auto& c : pairs_) {
      c.residual = Error::residual(c);
      c.weight = kernel_.weight(c.residual);
      sum += c.d2;
    }
    return pairs_.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(pairs_.size()));
  }

  template <Scalar S>
  IcpResult& finish(IcpResult& res, const Target<S>& target, const Isometry3d& t, Status status,
                    std::string message) {
    res.transform = t;
    res.status = status;
    res.message = std::move(message);
    res.rmse = correspond(target, t);
    res.inliers = pairs_.size();
    res.inlier_fraction =
        src_.empty() ? 0.0 : static_cast<double>(pairs_.size()) / static_cast<double>(src_.size());
    res.information.setZero();
    for (const auto& c : pairs_) Error::add_information(c, res.information);
    res.information = res.information.template selfadjointView<Eigen::Lower>();
    return res;
  }

  static constexpr index::PointId kNoHint = std::numeric_limits<index::PointId>::max();

  IcpConfig cfg_;
  Kernel kernel_;
  std::vector<Vec3d> src_;
  std::vector<Vec3d> coarse_;
  const std::vector<Vec3d>* active_ = &src_;
  bool approximate_ = false;
  std::vector<Correspondence> pairs_;
  std::vector<double> scratch_;
  // Each active point's last exact match (kNoHint: none), where the point was when that match
  // was searched, and the squared radius around there within which it stays the nearest (0:
  // search again).
  struct Match {
    index::PointId id = kNoHint;
    Vec3d at = Vec3d::Zero();
    double radius2 = 0.0;
  };
  std::vector<Match> matches_;
};

}  // namespace taxel::registration
