// SPDX-License-Identifier: MIT
// Fixed-size Eigen aliases used throughout taxel, templated on the scalar type.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

#include "taxel/core/concepts.hpp"
#include "taxel/core/deferred.hpp"

namespace taxel {

/// Column 3-vector (metres when it is a position).
template <Scalar S>
using Vec3 = Eigen::Matrix<S, 3, 1>;
/// 3x3 matrix (square metres when it is a position covariance).
template <Scalar S>
using Mat3 = Eigen::Matrix<S, 3, 3>;
/// Rigid transform; `T_a_b` maps coordinates in frame b into frame a.
template <Scalar S>
using Isometry3 = Eigen::Transform<S, 3, Eigen::Isometry>;

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;
using Mat3f = Mat3<float>;
using Mat3d = Mat3<double>;
using Isometry3f = Isometry3<float>;
using Isometry3d = Isometry3<double>;

/// True when every coefficient of a fixed-size vector or matrix is finite. A plain loop that
/// inlines (Eigen's allFinite is a non-inlined comparison of m - m in some builds); used on the
/// per-contact paths.
template <class Derived>
[[nodiscard]] constexpr bool all_finite(const Eigen::MatrixBase<Derived>& m) noexcept {
  bool ok = true;
  for (Eigen::Index j = 0; j < m.cols(); ++j) {
    for (Eigen::Index i = 0; i < m.rows(); ++i) ok &= std::isfinite(m.coeff(i, j));
  }
  return ok;
}

/// Why `T` is not a rigid transform, or nullptr when it is: every entry finite, the last row
/// (0, 0, 0, 1) to 1e-9, the upper-left 3x3 block a rotation (orthonormal to 1e-6, determinant
/// positive) and the translation within 1e150 (so that the points it moves stay finite). A
/// pose from forward kinematics or a pose file passes; a scaled, sheared, reflected or
/// uninitialised matrix does not.
template <Scalar S>
[[nodiscard]] const char* rigid_defect(const Isometry3<S>& T) noexcept {
  const auto& m = T.matrix();
  if (!all_finite(m)) return "the matrix is not finite";
  if (std::abs(m(3, 0)) > S(1e-9) || std::abs(m(3, 1)) > S(1e-9) || std::abs(m(3, 2)) > S(1e-9) ||
      std::abs(m(3, 3) - S(1)) > S(1e-9)) {
    return "the last row must be (0, 0, 0, 1)";
  }
  const Mat3<S> r = m.template topLeftCorner<3, 3>();
  if (!((r.transpose() * r - Mat3<S>::Identity()).cwiseAbs().maxCoeff() <= S(1e-6)) ||
      !(r.determinant() > S(0))) {
    return "the upper-left 3x3 block is not a rotation";
  }
  if (!(m.template topRightCorner<3, 1>().cwiseAbs().maxCoeff() <= S(1e150))) {
    return "the translation is beyond 1e150";
  }
  return nullptr;
}

}  // namespace taxel
