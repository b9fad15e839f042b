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

}  // namespace taxel
