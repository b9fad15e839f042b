// SPDX-License-Identifier: MIT
// Fixed-size Eigen aliases used throughout taxel, templated on the scalar type.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "taxel/core/concepts.hpp"

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

}  // namespace taxel
