// SPDX-License-Identifier: MIT
// Robust kernels for ICP as iteratively reweighted least squares: each policy maps a residual
// magnitude r (metres) to a weight w(r) = rho'(r) / r. `scale` is the kernel's width k [m].
#pragma once

#include <cmath>
#include <concepts>
#include <string_view>

namespace taxel::registration {

/// A robust kernel: `weight(r)` in [0, 1] for a residual magnitude r >= 0.
template <class K>
concept RobustKernel = requires(const K& k, double r) {
  { k.weight(r) } -> std::convertible_to<double>;
  { K::name } -> std::convertible_to<std::string_view>;
};

/// Plain least squares: every inlier weighs 1.
struct NoKernel {
  static constexpr std::string_view name = "none";  ///< Name in messages.
  /// Weight of a residual `r` [m] in iteratively reweighted least squares.
  [[nodiscard]] static constexpr double weight(double /*r*/) noexcept { return 1.0; }
};

/// Huber: quadratic within k, linear beyond (w = k / r).
struct Huber {
  static constexpr std::string_view name = "huber";  ///< Name in messages.
  double scale = 1e-3;  ///< Residual [m] where the kernel starts to down-weight.
  /// Weight of a residual `r` [m] in iteratively reweighted least squares.
  [[nodiscard]] double weight(double r) const noexcept { return r <= scale ? 1.0 : scale / r; }
};

/// Cauchy (Lorentzian): w = 1 / (1 + (r/k)^2).
struct Cauchy {
  static constexpr std::string_view name = "cauchy";  ///< Name in messages.
  double scale = 1e-3;  ///< Residual [m] where the kernel starts to down-weight.
  /// Weight of a residual `r` [m] in iteratively reweighted least squares.
  [[nodiscard]] double weight(double r) const noexcept {
    const double u = r / scale;
    return 1.0 / (1.0 + u * u);
  }
};

/// Geman-McClure: w = (k^2 / (k^2 + r^2))^2.
struct GemanMcClure {
  static constexpr std::string_view name = "geman-mcclure";  ///< Name in messages.
  double scale = 1e-3;  ///< Residual [m] where the kernel starts to down-weight.
  /// Weight of a residual `r` [m] in iteratively reweighted least squares.
  [[nodiscard]] double weight(double r) const noexcept {
    const double k2 = scale * scale;
    const double d = k2 / (k2 + r * r);
    return d * d;
  }
};

/// Tukey's biweight: w = (1 - (r/k)^2)^2 within k, 0 beyond (outliers drop out entirely).
struct Tukey {
  static constexpr std::string_view name = "tukey";  ///< Name in messages.
  double scale = 3e-3;  ///< Residual [m] where the kernel starts to down-weight.
  /// Weight of a residual `r` [m] in iteratively reweighted least squares.
  [[nodiscard]] double weight(double r) const noexcept {
    if (r >= scale) return 0.0;
    const double u = r / scale;
    return (1.0 - u * u) * (1.0 - u * u);
  }
};

}  // namespace taxel::registration
