// SPDX-License-Identifier: MIT
// Readings to contacts: the one place where a pad's readings and pose become contacts with
// positions, surface normals and measurement covariances. The simulator, the drivers and the
// tools all call it, so a recorded sensor and a simulated one go through the same arithmetic.
//
// The model, per active tactel (a reading k with threshold <= k < levels - 1):
//  1. Depth. The reading gives the measured compression m = k * full_scale_depth / (levels - 1).
//     Readings below the threshold are reported as zero, so a barely touching tactel survives
//     only when its depth noise is positive: the surviving readings are a truncated sample and
//     their mean lies above the true depth d by sigma * lambda((t - d) / sigma), with lambda the
//     inverse Mills ratio phi(a) / (1 - Phi(a)) of the normal distribution and t the threshold
//     depth (the mean of a truncated normal; Johnson, Kotz and Balakrishnan, Continuous
//     Univariate Distributions, vol. 1, 2nd ed., 1994, Sec. 10.1). The depth used is the plug-in
//     correction d = m - sigma * lambda((t - m) / sigma); it vanishes for readings a few sigma
//     above the threshold and its square is added to the depth variance.
//     The plug-in value is itself biased where it matters most: a tactel at the rim of the
//     contact (true depth near 0) that survives reads high, so lambda at its reading is too
//     small (E[d - true] = +0.07 mm at a true depth below 0.2 mm, sigma 0.3 mm). When more
//     than six tactels are active and a quadric in the pad plane fits their plug-in depths (a
//     chi-square test: the residuals' sum of squares below v (n - 6 + 3 sqrt(2 (n - 6))), so
//     not across an edge), the correction is evaluated instead at the depth f the quadric
//     predicts for the tactel, which the tactel's own noise barely moves:
//       d = m - sigma * lambda(a) + (h v / 2) lambda''(a) / sigma,   a = (t - f) / sigma,
//     the second term removing the bias of a curved correction evaluated at a noisy f (Jensen;
//     v the depth variance sigma^2 + dq^2 / 12 with dq the depth of one count, h the tactel's
//     leverage in the fit, so h v is f's variance). The quadric is refitted once to the corrected
//     depths and the correction evaluated again (a second pass; further passes drift, feeding each
//     fit's error back through lambda). The corrected depth's variance is then the truncated
//     normal's, v (1 - lambda'(a)), plus the fit's share, lambda'(a)^2 h v; with the plug-in
//     correction it is v + c^2 (c the correction).
//  2. Normal. A plane d(x, y) = a + g . (x, y) is fitted by least squares to the corrected
//     depths of the tactel and its active 8-neighbours; the surface in the pad frame is
//     z = -d(x, y), so its outward normal is -(g_x, g_y, 1) / |(g_x, g_y, 1)|. Where the active
//     neighbours span only a row or a column, the slope across it is taken as zero, and where
//     they span neither, the pad normal (-z) is used; a slope not measured gets the variance
//     fallback_normal_sigma^2.
//  3. Covariance. Tight along that normal, wide across it:
//       across:  s_t^2 = pitch^2 / 12 + sigma_position^2 + |xy|^2 sigma_tilt^2 / 6
//       along:   s_n^2 = var d + sigma_position^2
//                        + |xy|^2 sigma_tilt^2 / 3 + (pitch^2 / 12) (var g_x + var g_y)
//     (var d the corrected depth's variance of step 1, |xy| the tactel's lever arm from
//     the pad origin; the last term is the normal's own uncertainty: a plane tilted by beta
//     misstates the height by beta * u over a sideways offset u, and u spreads over the
//     tactel's footprint). The slope variances are the least-squares ones,
//     (sigma_normal^2 + dq^2 / 12) times the diagonal of the inverse normal matrix.
//  4. Position. The tactel centre pushed back by the corrected depth along the pad normal:
//     T_world_pad * (x, y, -d).
// Per pad, one contact per frame: a quadric d(x, y) = a + g . u + u' H u / 2 (u the offset from
// the centroid of the active tactels) is fitted to their corrected depths, and the contact is
// the fitted surface point above the centroid, with the fitted normal there and the fit's own
// variance of a and g. The centroid is not weighted by the readings: a reading's noise would
// then pull the centroid towards where the same noise has raised the fit, and the contact would
// sit outside a curved surface by about 2 sigma^2 / (n mean depth) (+0.02 mm on a 40 mm sphere
// pressed 1 mm). When the active tactels do not determine a quadric (fewer
// than six, or all in one or two rows), the frame gives one contact per active tactel instead:
// a plane or a mean fitted there would sit below a convex surface by the chord sag.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/types.hpp"
#include "taxel/sensor/pad.hpp"

namespace taxel::sensor {

/// How readings become contacts.
struct ContactOptions {
  ContactMode mode = ContactMode::per_tactel;  ///< a contact per active tactel, or per pad
  bool local_normals = true;      ///< normals from the depth map (false: the pad normal)
  bool correct_censoring = true;  ///< remove the truncation bias of near-threshold readings
  /// Evaluate that correction at the depth a pad-wide quadric predicts rather than at the
  /// reading (unbiased at the rim of a contact; about twice the cost per active tactel).
  bool refine_censoring = true;
  /// Angular standard deviation [rad] of a normal slope that the depth map cannot measure
  /// (too few active neighbours); > 0.
  double fallback_normal_sigma = 0.15;

  /// Throws std::invalid_argument naming the field out of range.
  void validate() const {
    if (!(fallback_normal_sigma > 0) || !std::isfinite(fallback_normal_sigma)) {
      throw std::invalid_argument("ContactOptions::fallback_normal_sigma must be finite and > 0");
    }
  }
};

/// The truncation bias [m] of a reading of measured depth `m` [m] that survived a threshold at
/// depth `t` [m] under Gaussian noise `sigma` [m]: sigma * lambda((t - m) / sigma), lambda the
/// inverse Mills ratio. Zero when sigma is zero or the reading is far above the threshold.
inline double truncation_bias(double m, double t, double sigma) noexcept {
  if (!(sigma > 0)) return 0.0;
  const double a = (t - m) / sigma;
  if (a < -9.0) return 0.0;                                        // below 1e-17 sigma
  const double survive = 0.5 * std::erfc(a * 0.7071067811865476);  // 1 - Phi(a)
  const double density = 0.3989422804014327 * std::exp(-0.5 * a * a);
  return sigma * density / survive;
}

/// Turns readings of one pad into contacts (see the model above). Holds a workspace, so
/// repeated calls allocate nothing beyond what `out` grows by. Not thread-safe: one extractor
/// per thread.
class ContactExtractor {
 public:
  /// Throws std::invalid_argument for an invalid model or options.
  explicit ContactExtractor(const SensorModel& model, const ContactOptions& options = {})
      : model_(model), options_(options) {
    model_.validate();
    options_.validate();
    const double dq = model_.depth_per_count();
    // Selection is round(measured / dq) >= threshold, i.e. measured >= (threshold - 1/2) dq.
    const double t = (model_.threshold - 0.5) * dq;
    const int saturated = model_.levels - 1;
    bias_.assign(static_cast<std::size_t>(saturated), 0.0);
    if (options_.correct_censoring) {
      for (int k = model_.threshold; k < saturated; ++k) {
        const double b = truncation_bias(k * dq, t, model_.sigma_normal);
        if (b == 0.0) break;
        bias_[static_cast<std::size_t>(k)] = b;
      }
    }
    depth_.assign(static_cast<std::size_t>(model_.geometry.rows) * model_.geometry.cols, kNone);
    var_.assign(depth_.size(), 0.0);
    plug_in_.assign(depth_.size(), 0.0);
    padded_.assign(static_cast<std::size_t>(model_.geometry.rows + 2) * (model_.geometry.cols + 2),
                   0.0);
    on_.assign(padded_.size(), 0);
    // lambda(a) and lambda''(a) on a grid of a (lambda' = lambda (lambda - a),
    // lambda'' = lambda' (lambda - a) + lambda (lambda' - 1)), for the refined correction.
    for (int i = 0; i < kTable; ++i) {
      const double a = kTableLow + i / kTableScale;
      const double lam = truncation_bias(-a, 0.0, 1.0);
      const double l1 = lam * (lam - a);
      lambda_[i][0] = lam;
      lambda_[i][1] = l1 * (lam - a) + lam * (l1 - 1.0);
    }
  }

  /// Appends the contacts of `counts` (rows x cols readings) taken with the pad at
  /// `T_world_pad` (pad -> world, as the robot believes it) at `time` [s] to `out`, in row-major
  /// tactel order. Returns the number appended. Throws std::invalid_argument when `counts`
  /// does not match the pad geometry or the pose is not finite.
  template <class = void>
  std::size_t extract(const PadMatrix& counts, const Eigen::Isometry3d& T_world_pad, double time,
                      std::vector<Contact<double>>& out) {
    const PadGeometry& g = model_.geometry;
    if (counts.rows() != g.rows || counts.cols() != g.cols) {
      throw std::invalid_argument("ContactExtractor: readings are " +
                                  std::to_string(counts.rows()) + " x " +
                                  std::to_string(counts.cols()) + ", the pad is " +
                                  std::to_string(g.rows) + " x " + std::to_string(g.cols));
    }
    if (!T_world_pad.matrix().allFinite()) {
      throw std::invalid_argument("ContactExtractor: the pad pose is not finite");
    }
    const int saturated = model_.levels - 1;
    const double dq = model_.depth_per_count();
    const double vd = depth_variance();
    std::size_t active = 0;
    for (int r = 0; r < g.rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        const int k = counts(r, c);
        double& d = depth_[static_cast<std::size_t>(r) * g.cols + c];
        if (k >= model_.threshold && k < saturated) {
          const double b = bias_[static_cast<std::size_t>(k)];
          d = k * dq - b;
          plug_in_[static_cast<std::size_t>(r) * g.cols + c] = b;
          var_[static_cast<std::size_t>(r) * g.cols + c] = vd + b * b;
          ++active;
        } else {
          d = kNone;
        }
      }
    }
    if (active == 0) return 0;
    if (options_.correct_censoring && options_.refine_censoring) refine_censoring();
    return options_.mode == ContactMode::per_tactel ? per_tactel(counts, T_world_pad, time, out)
                                                    : per_pad(counts, T_world_pad, time, out);
  }

  /// The sensor model in use.
  const SensorModel& model() const noexcept { return model_; }
  /// The options in use.
  const ContactOptions& options() const noexcept { return options_; }

 private:
  static constexpr double kNone = -std::numeric_limits<double>::infinity();

  double depth_variance() const {
    const double dq = model_.depth_per_count();
    return model_.sigma_normal * model_.sigma_normal + dq * dq / 12.0;
  }

  // The contact at pad point (x, y, -depth) with outward normal n_pad (pad frame), extra
  // variance along the normal and the slope variances of that normal.
  template <class = void>
  Contact<double> make(const Eigen::Isometry3d& T, double x, double y, double depth,
                       const Vec3d& n_pad, double var_along, double var_across, double slope_var,
                       double pressure, double time) const {
    const double lever2 = x * x + y * y;
    const double st2 = model_.sigma_tilt * model_.sigma_tilt;
    const double sp2 = model_.sigma_position * model_.sigma_position;
    const double vt = var_across + sp2 + lever2 * st2 / 6.0;
    const double vn = var_along + sp2 + lever2 * st2 / 3.0 + q2() * slope_var;
    Contact<double> c;
    c.position = T * Vec3d(x, y, -depth);
    Vec3d n = T.linear() * n_pad;       // unit already when T's rotation is orthonormal; made sure:
    const double n2 = n.squaredNorm();  // one Newton step for 1 / |n| when |n| is near 1
    n *= std::abs(n2 - 1.0) < 1e-6 ? 1.5 - 0.5 * n2 : 1.0 / std::sqrt(n2);
    c.covariance = Mat3d::Identity() * vt + (vn - vt) * (n * n.transpose());
    c.normal = n;
    c.pressure = pressure;
    c.time = time;
    return c;
  }

  template <class = void>
  std::size_t per_tactel(const PadMatrix& counts, const Eigen::Isometry3d& T, double time,
                         std::vector<Contact<double>>& out) const {
    const PadGeometry& g = model_.geometry;
    const double p = g.pitch;
    const double vd = depth_variance();
    const double fb2 = options_.fallback_normal_sigma * options_.fallback_normal_sigma;
    const double inv_p = 1.0 / p, inv_p2 = inv_p * inv_p;
    const std::size_t pc = static_cast<std::size_t>(g.cols) + 2;  // padded row length
    const std::array<PlaneWeights, 512>& weights = plane_weights();
    if (options_.local_normals) {
      // The depths and the active flags with a border of inactive tactels around the pad.
      for (int r = 0; r < g.rows; ++r) {
        for (int c = 0; c < g.cols; ++c) {
          const double d = depth_[static_cast<std::size_t>(r) * g.cols + c];
          const std::size_t at = static_cast<std::size_t>(r + 1) * pc + (c + 1);
          on_[at] = d != kNone;
          padded_[at] = d != kNone ? d : 0.0;
        }
      }
    }
    std::size_t added = 0;
    for (int r = 0; r < g.rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        const double d0 = depth_[static_cast<std::size_t>(r) * g.cols + c];
        if (d0 == kNone) continue;
        double gx = 0, gy = 0, vgx = 0, vgy = 0;  // slopes of d per metre and their variances
        if (options_.local_normals) {
          // Least-squares plane over the active 3x3 neighbourhood: linear in the depths, with
          // weights that depend only on which neighbours are active (plane_weights).
          const std::size_t at = static_cast<std::size_t>(r + 1) * pc + (c + 1);
          const std::size_t up = at - pc, down = at + pc;
          const double nd[9] = {padded_[up - 1],   padded_[up],   padded_[up + 1],
                                padded_[at - 1],   padded_[at],   padded_[at + 1],
                                padded_[down - 1], padded_[down], padded_[down + 1]};
          const unsigned mask = unsigned(on_[up - 1]) | unsigned(on_[up]) << 1 |
                                unsigned(on_[up + 1]) << 2 | unsigned(on_[at - 1]) << 3 | 1u << 4 |
                                unsigned(on_[at + 1]) << 5 | unsigned(on_[down - 1]) << 6 |
                                unsigned(on_[down]) << 7 | unsigned(on_[down + 1]) << 8;
          const PlaneWeights& w = weights[mask];
          for (int k = 0; k < 9; ++k) {
            gx += w.wx[k] * nd[k];
            gy += w.wy[k] * nd[k];
          }
          gx *= inv_p;
          gy *= inv_p;
          vgx = w.fx < 0 ? fb2 : vd * w.fx * inv_p2;
          vgy = w.fy < 0 ? fb2 : vd * w.fy * inv_p2;
        }
        // The outward normal -(gx, gy, 1) / |(gx, gy, 1)|, with one division.
        const double scale = -1.0 / std::sqrt(gx * gx + gy * gy + 1.0);
        const Vec3d n_pad(gx * scale, gy * scale, scale);
        const Vec3d at = g.tactel(r, c);
        const int k = counts(r, c);
        out.push_back(make(T, at.x(), at.y(), d0, n_pad,
                           var_[static_cast<std::size_t>(r) * g.cols + c], q2(), vgx + vgy,
                           double(k), time));
        ++added;
      }
    }
    return added;
  }

  // The refined censoring correction (the model above, step 1): quadric fit of the plug-in
  // depths, the correction evaluated at the fitted depth with its Jensen term, refitted once.
  // Leaves the plug-in depths when at most six tactels are active, the quadric is not
  // determined or it does not fit.
  template <class = void>
  void refine_censoring() {
    const PadGeometry& g = model_.geometry;
    const double dq = model_.depth_per_count();
    const double sigma = model_.sigma_normal;
    if (!(sigma > 0)) return;
    const double t = (model_.threshold - 0.5) * dq;
    const double x0 = 0.5 * (g.cols - 1), y0 = 0.5 * (g.rows - 1);
    // Pass 0's normal equations, on the plug-in depths.
    active_.clear();
    double ata[36] = {}, sol[6] = {};
    for (int r = 0; r < g.rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        const std::size_t i = static_cast<std::size_t>(r) * g.cols + c;
        const double d = depth_[i];
        if (d == kNone) continue;
        const double X = c - x0, Y = r - y0;
        const double row[6] = {1.0, X, Y, X * X, X * Y, Y * Y};
        for (int a = 0; a < 6; ++a) {
          sol[a] += row[a] * d;
          for (int b = 0; b <= a; ++b) ata[a * 6 + b] += row[a] * row[b];
        }
        active_.push_back({i, X, Y, d + plug_in_[i], 0.0});
      }
    }
    const double n = static_cast<double>(active_.size());
    double inv_diag[6];
    if (n < 7 || !detail_cholesky(ata, 6, inv_diag)) return;
    detail_solve(ata, 6, inv_diag, sol);
    const double vd = depth_variance();
    const double half_v_over_sigma = 0.5 * vd / sigma, inv_sigma = 1.0 / sigma;
    // The correction at fitted depth f: d = measured - sigma lambda(a) + jensen lambda''(a),
    // a = (t - f) / sigma, by linear interpolation in the tables (a clamped to their range; f
    // itself is not clamped at 0: the fit's noise is symmetric, a clamp would bias it), and
    // the variance of the corrected depth: the truncated normal's, sigma^2 (1 - lambda'),
    // plus the fit's share through the correction's slope lambda'.
    const auto correct = [&](const Active& e, double f) {
      const double a = (t - f) * inv_sigma;
      const double u = std::clamp((a - kTableLow) * kTableScale, 0.0, double(kTable - 1) - 1e-9);
      const int k = static_cast<int>(u);
      const double w = u - k;
      const double lam = lambda_[k][0] + w * (lambda_[k + 1][0] - lambda_[k][0]);
      const double l2 = lambda_[k][1] + w * (lambda_[k + 1][1] - lambda_[k][1]);
      const double l1 = lam * (lam - a);
      depth_[e.index] = e.measured - sigma * lam + e.jensen * l2;
      var_[e.index] = vd * (1.0 - l1) + l1 * l1 * e.jensen * 2.0 * sigma;
    };
    const auto fitted = [](const double* q, const Active& e) {
      return q[0] + e.x * (q[1] + q[3] * e.x + q[4] * e.y) + e.y * (q[2] + q[5] * e.y);
    };
    // Pass 0: leverages, residuals, corrections at the first fit, pass 1's right-hand side.
    double rss = 0, sol1[6] = {};
    for (Active& e : active_) {
      double y[6] = {1.0, e.x, e.y, e.x * e.x, e.x * e.y, e.y * e.y};
      double h = 0;
      for (int a = 0; a < 6; ++a) {  // leverage |L^-1 row|^2
        for (int b = 0; b < a; ++b) y[a] -= ata[a * 6 + b] * y[b];
        y[a] *= inv_diag[a];
        h += y[a] * y[a];
      }
      e.jensen = h * half_v_over_sigma;
      const double f = fitted(sol, e);
      const double res = depth_[e.index] - f;
      rss += res * res;
      correct(e, f);
      const double d = depth_[e.index];
      const double row[6] = {1.0, e.x, e.y, e.x * e.x, e.x * e.y, e.y * e.y};
      for (int a = 0; a < 6; ++a) sol1[a] += row[a] * d;
    }
    // A chi-square test of the residuals, at about 3 standard deviations of their sum.
    if (!(rss <= vd * (n - 6 + 3 * std::sqrt(2 * (n - 6))))) {
      // Not a quadric (an edge, a corner): back to the plug-in depths.
      for (const Active& e : active_) {
        const double b = plug_in_[e.index];
        depth_[e.index] = e.measured - b;
        var_[e.index] = vd + b * b;
      }
      return;
    }
    // Pass 1: the corrections at the refit.
    detail_solve(ata, 6, inv_diag, sol1);
    for (const Active& e : active_) correct(e, fitted(sol1, e));
  }

  double q2() const { return model_.geometry.pitch * model_.geometry.pitch / 12.0; }

  template <class = void>
  std::size_t per_pad(const PadMatrix& counts, const Eigen::Isometry3d& T, double time,
                      std::vector<Contact<double>>& out) const {
    const PadGeometry& g = model_.geometry;
    const double p = g.pitch;
    const double vd = depth_variance();
    const double x0 = 0.5 * (g.cols - 1), y0 = 0.5 * (g.rows - 1);
    // Centroid of the active tactels, in pitch units from the pad centre (see the model above),
    // and the sum of their readings (the contact's pressure).
    double w = 0, wx = 0, wy = 0, corr2 = 0;
    int n = 0;
    for (int r = 0; r < g.rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        if (depth_[static_cast<std::size_t>(r) * g.cols + c] == kNone) continue;
        const double k = counts(r, c);
        w += k;
        wx += c - x0;
        wy += r - y0;
        corr2 += var_[static_cast<std::size_t>(r) * g.cols + c] - vd;
        ++n;
      }
    }
    const double xc = wx / n, yc = wy / n;
    // Least squares of the depths on 1, X, Y, X^2, XY, Y^2 (X, Y from the centroid). A plane
    // or a mean cannot say how the surface curves, and its value above the centroid lies below
    // a convex surface by the chord sag (E[u'Hu] / 2 over the active tactels: about -0.15 mm
    // on a 15 mm sphere under a 3.4 mm pitch pad). So when fewer than six tactels are active,
    // or they do not determine a quadric (a pivot vanishes: one or two rows), the tactels give
    // their contacts one by one.
    if (n < 6) return per_tactel(counts, T, time, out);
    double ata[36] = {}, sol[6] = {}, inv_diag[3] = {};
    for (int r = 0; r < g.rows; ++r) {
      for (int c = 0; c < g.cols; ++c) {
        const double d = depth_[static_cast<std::size_t>(r) * g.cols + c];
        if (d == kNone) continue;
        const double X = c - x0 - xc, Y = r - y0 - yc;
        const double row[6] = {1.0, X, Y, X * X, X * Y, Y * Y};
        for (int i = 0; i < 6; ++i) {
          sol[i] += row[i] * d;
          for (int j = 0; j <= i; ++j) ata[i * 6 + j] += row[i] * row[j];
        }
      }
    }
    double inv_l[6];
    if (!detail_cholesky(ata, 6, inv_l)) return per_tactel(counts, T, time, out);
    detail_solve(ata, 6, inv_l, sol);
    for (int i = 0; i < 3; ++i) {
      double e[6] = {};
      e[i] = 1.0;
      detail_solve(ata, 6, inv_l, e);
      inv_diag[i] = e[i];
    }
    double gx = 0, gy = 0, slope_var = 0.0;
    if (options_.local_normals) {
      gx = sol[1] / p;
      gy = sol[2] / p;
      slope_var = vd * (inv_diag[1] + inv_diag[2]) / (p * p);
    }
    const Vec3d n_pad = -Vec3d(gx, gy, 1.0).normalized();
    const double var_a = vd * inv_diag[0] + std::max(corr2, 0.0) / (double(n) * n);
    out.push_back(make(T, xc * p, yc * p, sol[0], n_pad, var_a, q2(), slope_var, w, time));
    return 1;
  }

  // In-place Cholesky factor (lower triangle, row stride 6) of the leading m x m block, and the
  // reciprocals of its diagonal; false when a pivot is not positive relative to its diagonal
  // entry.
  static bool detail_cholesky(double* a, int m, double* inv_diag) {
    for (int j = 0; j < m; ++j) {
      double djj = a[j * 6 + j];
      for (int k = 0; k < j; ++k) djj -= a[j * 6 + k] * a[j * 6 + k];
      if (!(djj > 1e-10 * a[j * 6 + j])) return false;
      const double ljj = std::sqrt(djj);
      a[j * 6 + j] = ljj;
      inv_diag[j] = 1.0 / ljj;
      for (int i = j + 1; i < m; ++i) {
        double v = a[i * 6 + j];
        for (int k = 0; k < j; ++k) v -= a[i * 6 + k] * a[j * 6 + k];
        a[i * 6 + j] = v * inv_diag[j];
      }
    }
    return true;
  }
  // Solves L L' x = b in place with the factor of detail_cholesky.
  static void detail_solve(const double* l, int m, const double* inv_diag, double* b) {
    for (int i = 0; i < m; ++i) {
      for (int k = 0; k < i; ++k) b[i] -= l[i * 6 + k] * b[k];
      b[i] *= inv_diag[i];
    }
    for (int i = m - 1; i >= 0; --i) {
      for (int k = i + 1; k < m; ++k) b[i] -= l[k * 6 + i] * b[k];
      b[i] *= inv_diag[i];
    }
  }

  SensorModel model_;
  ContactOptions options_;
  std::vector<double> bias_;     // truncation bias by reading count [m]
  std::vector<double> depth_;    // corrected depth per tactel [m]; kNone when not active
  std::vector<double> var_;      // its variance [m^2], for active tactels
  std::vector<double> plug_in_;  // the plug-in correction [m], for active tactels
  // The refined correction's workspace: an active tactel, its pad coordinates (pitch units from
  // the pad centre), measured depth [m] and Jensen factor h v / (2 sigma) [m].
  struct Active {
    std::size_t index;
    double x, y, measured, jensen;
  };
  std::vector<Active> active_;
  // per_tactel's workspace: depths (0 where inactive) and active flags of the pad with a
  // border of inactive tactels, (rows + 2) x (cols + 2).
  mutable std::vector<double> padded_;
  mutable std::vector<unsigned char> on_;

  // The plane fit of step 2 for one pattern of active neighbours (bit 3 (dr + 1) + (dc + 1) of
  // the 3x3 neighbourhood, the centre always set): the slopes in pitch units are
  // sum_k wx[k] d_k and sum_k wy[k] d_k, and their variances (depth variance) * f / pitch^2,
  // f < 0 meaning not measured (the fallback variance).
  struct PlaneWeights {
    double wx[9], wy[9];
    double fx, fy;
  };
  static const std::array<PlaneWeights, 512>& plane_weights() {
    static const std::array<PlaneWeights, 512> table = [] {
      std::array<PlaneWeights, 512> t{};
      for (unsigned mask = 0; mask < 512; ++mask) {
        PlaneWeights& w = t[mask];
        double n = 0, sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
        for (int k = 0; k < 9; ++k) {
          if (!(mask >> k & 1u)) continue;
          const double dc = k % 3 - 1, dr = k / 3 - 1;
          n += 1;
          sx += dc;
          sy += dr;
          sxx += dc * dc;
          syy += dr * dr;
          sxy += dc * dr;
        }
        w.fx = w.fy = -1.0;
        if (n == 0) continue;
        const double mx = sx / n, my = sy / n;
        const double cxx = sxx - sx * mx, cyy = syy - sy * my, cxy = sxy - sx * my;
        const double det = cxx * cyy - cxy * cxy;
        constexpr double kTiny = 1e-9;
        for (int k = 0; k < 9; ++k) {
          if (!(mask >> k & 1u)) continue;
          const double ux = k % 3 - 1 - mx, uy = k / 3 - 1 - my;
          if (cxx > kTiny && cyy > kTiny && det > 0.1 * cxx * cyy) {
            w.wx[k] = (cyy * ux - cxy * uy) / det;
            w.wy[k] = (cxx * uy - cxy * ux) / det;
            w.fx = cyy / det;
            w.fy = cxx / det;
          } else if (cxx > kTiny && std::abs(cxy) <= kTiny) {  // a row: x slope only
            w.wx[k] = ux / cxx;
            w.fx = 1.0 / cxx;
          } else if (cyy > kTiny && std::abs(cxy) <= kTiny) {  // a column: y slope only
            w.wy[k] = uy / cyy;
            w.fy = 1.0 / cyy;
          }
        }
      }
      return t;
    }();
    return table;
  }
  // lambda and lambda'' tabulated at a = kTableLow + i / kTableScale.
  static constexpr int kTable = 641;  // a in [-12, 8]
  static constexpr double kTableLow = -12.0, kTableScale = 32.0;
  double lambda_[kTable][2] = {};
};

}  // namespace taxel::sensor
