// SPDX-License-Identifier: MIT
// A tactile contact measurement and helpers for its measurement covariance.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "taxel/core/types.hpp"

namespace taxel {

/// One 3-D contact point as measured by a tactile sensor, in the world frame.
/// Trivially copyable; 152 bytes for double, 88 for float.
template <Scalar S>
struct Contact {
  Vec3<S> position = Vec3<S>::Zero();  ///< contact location [m], world frame
  /// Measurement covariance of `position` [m^2]; symmetric positive definite.
  /// Default: isotropic, 1 mm standard deviation.
  Mat3<S> covariance = Mat3<S>::Identity() * S(1e-6);
  std::optional<Vec3<S>> normal;  ///< unit outward pad normal [-], world frame, if known
  S pressure = S(0);              ///< contact pressure [Pa], or the sensor's raw units
  double time = 0.0;              ///< acquisition time [s]
  /// Angular standard deviation of `normal` [rad], >= 0; 0 (the default) when not stated, so
  /// that a fusion policy uses its own (`fusion::Surfel::Config::normal_sigma`). A normal the
  /// sensor could not measure (a lone tactel: the pad's own normal) states a large one.
  S normal_sigma = S(0);
  /// How much of the covariance across the normal is the contact's footprint rather than
  /// scatter: a standard deviation [m], >= 0. A footprint is where on the surface the contact
  /// stands for, around a position that lies on the surface (a tactel of pitch p read at its
  /// centre: p / sqrt(12), `tactel_sigma`). Scatter is how far the reported position strayed
  /// along the tangent plane (a pose error, a camera's or a kinematic model's noise), which
  /// lifts a contact off a curved surface. 0 (the default): all of it is scatter.
  S footprint_sigma = S(0);
};

/// Standard deviation [m] of a uniform quantisation over one tactel of the given pitch [m]:
/// pitch / sqrt(12).
template <Scalar S>
constexpr S tactel_sigma(S pitch) noexcept {
  return pitch / S(3.4641016151377545870548926830117);
}

/// Isotropic covariance sigma^2 * I [m^2] for a standard deviation sigma [m].
template <Scalar S>
Mat3<S> isotropic_covariance(S sigma) {
  if (!(sigma > S(0)) || !std::isfinite(sigma)) {
    throw std::invalid_argument("isotropic_covariance: sigma must be finite and > 0");
  }
  return Mat3<S>::Identity() * (sigma * sigma);
}

/// Anisotropic pad covariance [m^2]: standard deviation `sigma_normal` along `normal` and
/// `sigma_tangent` in the plane orthogonal to it, i.e.
/// sigma_t^2 I + (sigma_n^2 - sigma_t^2) n n^T with n = normal / |normal|.
/// Eigenvalues: sigma_n^2 (eigenvector n) and sigma_t^2 (twice, the pad plane).
/// Throws std::invalid_argument for a zero or non-finite normal or non-positive sigmas.
template <Scalar S>
Mat3<S> pad_covariance(const Vec3<S>& normal, S sigma_normal, S sigma_tangent) {
  const S len = normal.norm();
  if (!std::isfinite(len) || !(len > S(0))) {
    throw std::invalid_argument("pad_covariance: normal must be finite and non-zero");
  }
  if (!(sigma_normal > S(0)) || !(sigma_tangent > S(0)) || !std::isfinite(sigma_normal) ||
      !std::isfinite(sigma_tangent)) {
    throw std::invalid_argument(
        "pad_covariance: sigma_normal and sigma_tangent must be finite and > 0");
  }
  const Vec3<S> n = normal / len;
  const S sn2 = sigma_normal * sigma_normal;
  const S st2 = sigma_tangent * sigma_tangent;
  return Mat3<S>::Identity() * st2 + (sn2 - st2) * (n * n.transpose());
}

/// Why a contact cannot be used; `ok` when it can.
enum class ContactDefect {
  ok,
  non_finite_position,    ///< position has NaN or Inf
  non_finite_covariance,  ///< covariance has NaN or Inf
  asymmetric_covariance,  ///< covariance differs from its transpose beyond rounding
  indefinite_covariance,  ///< covariance is not positive definite
  bad_normal,             ///< normal is present but not finite or not of unit length (1e-3)
  overflow,               ///< fusing it would overflow the model (extreme magnitudes)
  non_finite_time,        ///< time is NaN or Inf
  non_finite_pressure,    ///< pressure is NaN or Inf
  out_of_range,           ///< position beyond what the cloud's index separates exactly
  bad_normal_sigma,       ///< normal_sigma is negative, NaN or Inf
  bad_footprint_sigma,    ///< footprint_sigma is negative, NaN or Inf
};

/// Short description of a contact defect.
constexpr std::string_view to_string(ContactDefect d) noexcept {
  switch (d) {
    case ContactDefect::ok:
      return "ok";
    case ContactDefect::non_finite_position:
      return "position is not finite";
    case ContactDefect::non_finite_covariance:
      return "covariance is not finite";
    case ContactDefect::asymmetric_covariance:
      return "covariance is not symmetric";
    case ContactDefect::indefinite_covariance:
      return "covariance is not positive definite";
    case ContactDefect::bad_normal:
      return "normal is not a finite unit vector";
    case ContactDefect::overflow:
      return "fusing it would overflow";
    case ContactDefect::non_finite_time:
      return "time is not finite";
    case ContactDefect::non_finite_pressure:
      return "pressure is not finite";
    case ContactDefect::out_of_range:
      return "position is beyond the index's range";
    case ContactDefect::bad_normal_sigma:
      return "normal_sigma is not finite and >= 0";
    case ContactDefect::bad_footprint_sigma:
      return "footprint_sigma is not finite and >= 0";
  }
  return "unknown";
}

namespace detail {
/// Sylvester's criterion on a matrix already known to be symmetric.
template <Scalar S>
bool leading_minors_positive(const Mat3<S>& m) noexcept {
  const S minor2 = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
  return m(0, 0) > S(0) && minor2 > S(0) && m.determinant() > S(0);
}
}  // namespace detail

/// True when `m` equals its transpose to within 64 ulps of its largest entry.
template <Scalar S>
bool is_symmetric(const Mat3<S>& m) noexcept {
  S largest = S(0);
  for (Eigen::Index i = 0; i < 9; ++i) largest = std::max(largest, std::abs(m.data()[i]));
  const S tol = S(64) * std::numeric_limits<S>::epsilon() * largest;
  return std::abs(m(0, 1) - m(1, 0)) <= tol && std::abs(m(0, 2) - m(2, 0)) <= tol &&
         std::abs(m(1, 2) - m(2, 1)) <= tol;
}

/// True when `m` is symmetric (see `is_symmetric`) and positive definite by Sylvester's
/// criterion (all leading principal minors > 0). O(1), no allocation.
template <Scalar S>
bool is_symmetric_positive_definite(const Mat3<S>& m) noexcept {
  return is_symmetric(m) && detail::leading_minors_positive(m);
}

/// Checks a contact for the defects that would corrupt a model fed with it. O(1).
template <Scalar S>
ContactDefect check_contact(const Contact<S>& c) noexcept {
  if (!all_finite(c.position)) return ContactDefect::non_finite_position;
  if (!all_finite(c.covariance)) return ContactDefect::non_finite_covariance;
  if (!is_symmetric(c.covariance)) return ContactDefect::asymmetric_covariance;
  if (!detail::leading_minors_positive(c.covariance)) return ContactDefect::indefinite_covariance;
  if (c.normal) {
    // |n| within 1e-3 of 1, on the squared norm; NaN and Inf fail the comparison.
    const S n2 = c.normal->squaredNorm();
    if (!(n2 >= S(0.999 * 0.999) && n2 <= S(1.001 * 1.001))) return ContactDefect::bad_normal;
  }
  if (!(c.normal_sigma >= S(0)) || !std::isfinite(c.normal_sigma)) {
    return ContactDefect::bad_normal_sigma;
  }
  if (!(c.footprint_sigma >= S(0)) || !std::isfinite(c.footprint_sigma)) {
    return ContactDefect::bad_footprint_sigma;
  }
  if (!std::isfinite(c.time)) return ContactDefect::non_finite_time;
  if (!std::isfinite(c.pressure)) return ContactDefect::non_finite_pressure;
  return ContactDefect::ok;
}

/// `c` with its fields converted to scalar type T.
template <Scalar T, Scalar S>
Contact<T> contact_cast(const Contact<S>& c) {
  Contact<T> out;
  out.position = c.position.template cast<T>();
  out.covariance = c.covariance.template cast<T>();
  if (c.normal) out.normal = c.normal->template cast<T>();
  out.pressure = static_cast<T>(c.pressure);
  out.time = c.time;
  out.normal_sigma = static_cast<T>(c.normal_sigma);
  out.footprint_sigma = static_cast<T>(c.footprint_sigma);
  return out;
}

}  // namespace taxel
