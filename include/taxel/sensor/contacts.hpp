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
//     fit's error back through lambda). The variance a contact states for its depth is v where
//     the refined correction applies, and v + c_t^2 with the plug-in one (c_t the plug-in
//     correction of a reading at the threshold, the largest it makes: what it leaves is up to
//     that size). Neither follows the tactel's own reading. A variance computed from it (the
//     truncated normal's v (1 - lambda'(a)) at the fitted depth, or v + c^2 with the tactel's
//     own correction c) moves with the reading's noise, so the fusion's weights 1 / variance
//     would favour the readings whose noise pushed them one way: the contacts a Surfel or Kalman
//     point averages would then sit -0.003..-0.010 mm inside the surface, weighted, where their
//     plain mean is within +-0.006 mm (measured on the pad streams of a 40 mm sphere, an
//     ellipsoid and a torus). The per-pad contact (below) keeps those variances, summed over
//     the frame.
//  2. Normal. The surface in the pad frame is z = -d(x, y), so with g the gradient of the depth
//     its outward normal is -(g_x, g_y, 1) / |(g_x, g_y, 1)|. Where the refined correction of
//     step 1 fitted its quadric (and the chi-square test passed), g is that quadric's gradient
//     at the tactel. Otherwise a plane d(x, y) = a + g . (x, y) is fitted by least squares to
//     the corrected depths of the tactel and its active 8-neighbours: its slope is exact on a
//     plane and at the centre of a full neighbourhood, but at the rim of a contact it belongs
//     to the centroid of the active neighbours, inward of the tactel, and flattens the normal
//     (slopes of 0.6-0.9 times the true ones for tactels with 3-7 active neighbours on a 40 mm
//     sphere, against 0.93-0.98 from the quadric). Where the active neighbours span only a row
//     or a column, the plane's slope across it is taken as zero, and where they span neither,
//     the pad normal (-z) is used; a slope not measured gets the variance
//     fallback_normal_sigma^2 (without local_normals, both slopes of every contact). The
//     pad's kinematic tilt turns the normal as well: an angle sigma_tilt about a uniform axis
//     tilts it by 2/3 sigma_tilt^2 in mean square, which is added to the slope variances. The
//     contact states the square root of that sum as its normal's uncertainty (normal_sigma).
//  3. Covariance. Tight along that normal, wide across it (the pitch^2 / 12 across is where
//     on the surface the contact stands for, stated as its footprint, Contact::footprint_sigma;
//     the pose's terms are scatter):
//       across:  s_t^2 = pitch^2 / 12 + sigma_position^2 + |xy|^2 sigma_tilt^2 / 6
//       along:   s_n^2 = var d + sigma_position^2
//                        + |xy|^2 sigma_tilt^2 / 3 + (pitch^2 / 12) normal_sigma^2
//     (var d the corrected depth's variance of step 1, |xy| the tactel's lever arm from
//     the pad origin; s_t^2 is kept at least 1e-6 s_n^2 and s_n^2 at least 1e-12 s_t^2, so
//     that the covariance stays positive definite in floating point, which only models far
//     from any tactile pad reach; the last term is the normal's own uncertainty: a plane tilted by
//     beta misstates the height by beta * u over a sideways offset u, and u spreads over the
//     tactel's footprint). The slope variances are the least-squares ones of the quadric or
//     the plane, (sigma_normal^2 + dq^2 / 12) e' A^-1 e with A the fit's normal matrix and e
//     the derivative of its row of monomials. For the quadric this leaves out how the censoring
//     correction amplifies the rim tactels' noise through the fit (a corrected depth rises with
//     the fitted one): its slopes scatter about 1.3 times the stated variance (tested), which
//     is about 0.4 % of the variance along the normal.
//  4. Position. The tactel centre pushed back by the corrected depth along the pad normal:
//     T_world_pad * (x, y, -d).
//  5. Footprint (ContactOptions::tactel_area). A real tactel reads the mean compression over
//     its area. Over a square of side p, a quadric compression q has the mean
//     q(centre) + p^2 / 24 (q_xx + q_yy): a fully touching tactel on a convex surface of radius
//     R reads p^2 / (12 R) less than at its centre (0.024 mm at R = 40 mm, p = 3.4 mm), and its
//     contact sits inside. A tactel at the rim of the touch reads the mean of max(q, 0), the
//     touching part's, deeper than its centre's (which may not touch at all), and its contact
//     sits outside. So the quadric of step 1 is fitted to the readings, its constant moved by
//     -(q_xx + q_yy) p^2 / 24 to describe the centres, and each tactel's expected reading f is
//     the mean of max(q, 0) over its square (the closed form where q is positive at the four
//     corners, otherwise 4 x 4 Gauss-Legendre points). The censoring correction is evaluated at
//     that f, and the depth is moved by q(centre) - f. Both passes of step 1 do this, so the
//     refit and the normals describe the centres. Frames without that quadric (too few active
//     tactels, no noise, or an edge) keep their readings as they are.
// Per pad, one contact per frame: a quadric d(x, y) = a + g . u + u' H u / 2 (u the offset from
// the centroid of the active tactels) is fitted to their corrected depths, and the contact is
// the fitted surface point above the centroid, with the fitted normal there and the fit's own
// variance of a and g. The centroid is not weighted by the readings: a reading's noise would
// then pull the centroid towards where the same noise has raised the fit, and the contact would
// sit outside a curved surface by about 2 sigma^2 / (n mean depth) (+0.02 mm on a 40 mm sphere
// pressed 1 mm). When the active tactels do not determine a quadric (fewer
// than six, or all in one or two rows), the frame gives one contact per active tactel instead:
// a plane or a mean fitted there would sit below a convex surface by the chord sag. So does a
// frame whose depths the quadric does not fit (with depth noise, step 1's chi-square test
// taken at 7 standard deviations instead of 3: a patch wider than a quadric follows, as a pad
// across a torus's tube, whose point above the centroid lay +0.11 mm outside on average).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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
  /// A reading is the mean compression over the tactel's pitch x pitch square, as a real
  /// tactel's is (`sim::read_pad` with a footprint of 2 or more), not the compression at its
  /// centre. Where the refined correction fits its quadric, each depth is moved to the centre's
  /// by the footprint excess of that quadric (the model above, step 5); elsewhere the reading
  /// is taken as it is.
  bool tactel_area = false;
  /// Angular standard deviation [rad] of a normal slope that the depth map cannot measure
  /// (too few active neighbours, or every slope without local_normals); > 0.
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
    censor_depth_ = t;
    inv_sigma_ = model_.sigma_normal > 0 ? 1.0 / model_.sigma_normal : 0.0;
    const int saturated = model_.levels - 1;
    bias_.assign(static_cast<std::size_t>(saturated), 0.0);
    if (options_.correct_censoring) {
      for (int k = model_.threshold; k < saturated; ++k) {
        const double b = truncation_bias(k * dq, t, model_.sigma_normal);
        if (b == 0.0) break;
        bias_[static_cast<std::size_t>(k)] = b;
      }
    }
    const std::size_t tactels =
        static_cast<std::size_t>(model_.geometry.rows) * model_.geometry.cols;
    active_.resize(tactels);
    listed_.resize(tactels + 8);
    cell_.resize(tactels);
    for (std::size_t i = 0; i < tactels; ++i) {
      const std::size_t cols = static_cast<std::size_t>(model_.geometry.cols);
      cell_[i] = (i / cols + 1) * (cols + 2) + i % cols + 1;
    }
    // The monomials of the quadric fit per tactel (pad coordinates in pitch units are
    // half-integers, so their sums are exact in any order).
    monomials_.resize(tactels);
    for (int r = 0; r < model_.geometry.rows; ++r) {
      for (int c = 0; c < model_.geometry.cols; ++c) {
        const double X = c - 0.5 * (model_.geometry.cols - 1),
                     Y = r - 0.5 * (model_.geometry.rows - 1);
        const double X2 = X * X, Y2 = Y * Y;
        monomials_[static_cast<std::size_t>(r) * model_.geometry.cols + c] = {
            1.0,     X,          Y,       X2,         X * Y,   Y2,
            X2 * X,  X2 * Y,     X * Y2,  Y2 * Y,  //
            X2 * X2, X2 * X * Y, X2 * Y2, X * Y2 * Y, Y2 * Y2, 0.0};
      }
    }
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
    // Each entry's differences to the next, so that an interpolation reads one entry.
    for (int i = 0; i + 1 < kTable; ++i) {
      lambda_[i][2] = lambda_[i + 1][0] - lambda_[i][0];
      lambda_[i][3] = lambda_[i + 1][1] - lambda_[i][1];
    }
  }

  /// Appends the contacts of `counts` (rows x cols readings) taken with the pad at
  /// `T_world_pad` (pad -> world, as the robot believes it) at `time` [s] to `out`, in row-major
  /// tactel order. Returns the number appended. Throws std::invalid_argument when `counts`
  /// does not match the pad geometry or the pose is not a rigid transform (rigid_defect).
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
    if (const char* why = rigid_defect(T_world_pad)) {
      throw std::invalid_argument(std::string("ContactExtractor: the pad pose is not a rigid "
                                              "transform: ") +
                                  why);
    }
    // The previous frame's active cells back to inactive, the list of active tactels by a
    // branch-free pass over the readings, then their plug-in depths into the padded grid.
    for (std::size_t i = 0; i < active_count_; ++i) {
      padded_[active_[i].at] = 0.0;
      on_[active_[i].at] = 0;
    }
    const int saturated = model_.levels - 1;
    const double dq = model_.depth_per_count();
    const double vd = depth_variance();
    const std::uint16_t* reading = counts.data();
    const std::size_t tactels = static_cast<std::size_t>(g.rows) * g.cols;
    // (Active means threshold <= k < saturated, one unsigned comparison of k - threshold; the
    // bounds are held in locals, since the stores to listed_ may alias model_.)
    const unsigned threshold = static_cast<unsigned>(model_.threshold),
                   span = static_cast<unsigned>(saturated - model_.threshold);
    std::uint32_t* listed = listed_.data();
    std::size_t n = 0, i = 0;
#if defined(__SSE2__)
    // Eight readings at a time: the unsigned comparison as a signed one of the values with
    // their sign bits flipped, the active lanes as a byte mask, and their indices from a
    // table of the 256 masks (listed_ has room for the eight written past the last).
    {
      const __m128i zero = _mm_setzero_si128(), lo = _mm_set1_epi16(static_cast<short>(threshold));
      const __m128i flip = _mm_set1_epi16(static_cast<short>(-32768));
      const __m128i hi = _mm_set1_epi16(static_cast<short>(static_cast<int>(span) - 32768));
      const auto& lanes = active_lanes();
      for (; i + 8 <= tactels; i += 8) {
        const __m128i k = _mm_loadu_si128(reinterpret_cast<const __m128i*>(reading + i));
        const __m128i on = _mm_cmplt_epi16(_mm_xor_si128(_mm_sub_epi16(k, lo), flip), hi);
        const auto mask = static_cast<unsigned>(_mm_movemask_epi8(_mm_packs_epi16(on, zero)));
        const Lanes& l = lanes[mask];
        const __m128i at16 =
            _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(l.index)), zero);
        const __m128i base = _mm_set1_epi32(static_cast<int>(i));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(listed + n),
                         _mm_add_epi32(_mm_unpacklo_epi16(at16, zero), base));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(listed + n + 4),
                         _mm_add_epi32(_mm_unpackhi_epi16(at16, zero), base));
        n += l.count;
      }
    }
#endif
    for (; i < tactels; ++i) {
      listed[n] = static_cast<std::uint32_t>(i);
      n += (reading[i] - threshold) < span;
    }
    for (std::size_t j = 0; j < n; ++j) {
      const std::size_t t = listed[j];
      const int k = reading[t];
      const std::size_t at = cell_[t];
      const double b = bias_[static_cast<std::size_t>(k)];
      const double m = k * dq;
      padded_[at] = m - b;
      on_[at] = 1;
      active_[j] = {at, t, monomials_[t][1], monomials_[t][2], m, 0.0, vd + b * b, b, double(k)};
    }
    active_count_ = n;
    factored_ = false;
    quad_ok_ = false;
    refined_ = false;
    if (n == 0) return 0;
    if (options_.correct_censoring && options_.refine_censoring) refine_censoring();
    return options_.mode == ContactMode::per_tactel ? per_tactel(T_world_pad, time, out)
                                                    : per_pad(T_world_pad, time, out);
  }

  /// The sensor model in use.
  const SensorModel& model() const noexcept { return model_; }
  /// The options in use.
  const ContactOptions& options() const noexcept { return options_; }

 private:
  // An active tactel: its cell in the padded grid, its index, pad coordinates (pitch units from
  // the pad centre; monomials_ has them too, kept here beside the rest of what the loops read),
  // measured depth [m], Jensen factor h v / (2 sigma) of the refined correction [m], corrected
  // depth's variance [m^2] (read by the per-pad contact), plug-in correction [m] and reading.
  struct Active {
    std::size_t at, tactel;
    double x, y, measured, jensen, var, plug_in, pressure;
  };

  double depth_variance() const {
    const double dq = model_.depth_per_count();
    return model_.sigma_normal * model_.sigma_normal + dq * dq / 12.0;
  }

  // The noise terms every contact of a frame shares (see the model above, step 3), read once
  // per frame: sigma_position^2, sigma_tilt^2 / 6 and / 3, pitch^2 / 12 and its square root
  // (the footprint a contact states).
  struct SharedNoise {
    double sp2, st2_6, st2_3, q2, footprint;
  };
  SharedNoise shared_noise() const {
    const double st2 = model_.sigma_tilt * model_.sigma_tilt;
    return {model_.sigma_position * model_.sigma_position, st2 / 6.0, st2 / 3.0, q2(),
            tactel_sigma(model_.geometry.pitch)};
  }

  // The contact at pad point (x, y, -depth) with outward normal n_pad (pad frame), extra
  // variance along the normal and the slope variances of that normal.
  template <class = void>
  [[gnu::always_inline]] void make(std::vector<Contact<double>>& out, const Eigen::Isometry3d& T,
                                   const SharedNoise& sn, double x, double y, double depth,
                                   const Vec3d& n_pad, double var_along, double slope_var,
                                   double pressure, double time) const {
    const double lever2 = x * x + y * y;
    slope_var += 2.0 * sn.st2_3;  // the pad's own tilt turns the normal too
    const double vt0 = sn.q2 + sn.sp2 + lever2 * sn.st2_6;
    const double vn0 = var_along + sn.sp2 + lever2 * sn.st2_3 + sn.q2 * slope_var;
    // (Each kept within a bound of the other, which no tactile pad comes near, so that the
    // covariance stays positive definite in floating point: a model without noise and with a
    // vanishing depth per count would state nothing along the normal, and a micrometre pitch
    // under a metre of depth noise next to nothing across.)
    const double vt = std::max(vt0, 1e-6 * vn0);
    const double vn = std::max(vn0, 1e-12 * vt);
    Vec3d n = T.linear() * n_pad;       // unit already when T's rotation is orthonormal; made sure:
    const double n2 = n.squaredNorm();  // one Newton step for 1 / |n| when |n| is near 1
    n *= std::abs(n2 - 1.0) < 1e-6 ? 1.5 - 0.5 * n2 : 1.0 / std::sqrt(n2);
    // vt I + (vn - vt) n n', written out (symmetric).
    const double dv = vn - vt;
    const double cxy = dv * n.x() * n.y(), cxz = dv * n.x() * n.z(), cyz = dv * n.y() * n.z();
    Mat3d cov;
    cov << vt + dv * n.x() * n.x(), cxy, cxz, cxy, vt + dv * n.y() * n.y(), cyz, cxz, cyz,
        vt + dv * n.z() * n.z();
    out.push_back(Contact<double>{T * Vec3d(x, y, -depth), cov, n, pressure, time,
                                  std::sqrt(slope_var), sn.footprint});
  }

  template <class = void>
  std::size_t per_tactel(const Eigen::Isometry3d& T, double time,
                         std::vector<Contact<double>>& out) const {
    const PadGeometry& g = model_.geometry;
    const double p = g.pitch;
    const double vd = depth_variance();
    const double fb2 = options_.fallback_normal_sigma * options_.fallback_normal_sigma;
    const double inv_p = 1.0 / p, inv_p2 = inv_p * inv_p;
    const std::size_t pc = static_cast<std::size_t>(g.cols) + 2;  // padded row length
    const std::array<PlaneWeights, 512>& weights = plane_weights();
    // The depth variance every contact of the frame states (the model above, step 1).
    const auto at_threshold = static_cast<std::size_t>(model_.threshold);
    const double threshold_bias = at_threshold < bias_.size() ? bias_[at_threshold] : 0.0;
    const double var_depth = refined_ ? vd : vd + threshold_bias * threshold_bias;
    const SharedNoise sn = shared_noise();
    const Censoring cens = censoring();
    const double* q = quad_;
    const double* f = slope_var_;
    for (std::size_t i = 0; i < active_count_; ++i) {
      const Active& e = active_[i];
      // Slopes of d per metre and the sum of their variances (unmeasured: the pad's normal).
      double gx = 0, gy = 0, vg = 2.0 * fb2;
      double depth = padded_[e.at];
      if (quad_ok_) {
        // The pad-wide quadric's gradient at the tactel and its least-squares variances, and
        // the depth corrected at the quadric's (refine_censoring's last pass).
        const double x = e.x, y = e.y;
        gx = (q[1] + 2 * q[3] * x + q[4] * y) * inv_p;
        gy = (q[2] + q[4] * x + 2 * q[5] * y) * inv_p;
        vg = f[0] + x * (f[1] + f[3] * x + f[4] * y) + y * (f[2] + f[5] * y);
        depth = centre_depth(cens, q, e);
      } else if (options_.local_normals) {
        // Least-squares plane over the active 3x3 neighbourhood: linear in the depths, with
        // weights that depend only on which neighbours are active (plane_weights).
        const std::size_t at = e.at, up = at - pc, down = at + pc;
        const double* u = &padded_[up - 1];
        const double* m = &padded_[at - 1];
        const double* v = &padded_[down - 1];
        const unsigned mask = unsigned(on_[up - 1]) | unsigned(on_[up]) << 1 |
                              unsigned(on_[up + 1]) << 2 | unsigned(on_[at - 1]) << 3 | 1u << 4 |
                              unsigned(on_[at + 1]) << 5 | unsigned(on_[down - 1]) << 6 |
                              unsigned(on_[down]) << 7 | unsigned(on_[down + 1]) << 8;
        const PlaneWeights& w = weights[mask];
        // Inactive cells hold 0, so the sums over the whole 3x3 block are the active ones'.
        const double sum = (u[0] + u[1] + u[2]) + (m[0] + m[1] + m[2]) + (v[0] + v[1] + v[2]);
        const double sum_x = (u[2] + m[2] + v[2]) - (u[0] + m[0] + v[0]);
        const double sum_y = (v[0] + v[1] + v[2]) - (u[0] + u[1] + u[2]);
        gx = (w.x[0] * sum_x + w.x[1] * sum_y + w.x[2] * sum) * inv_p;
        gy = (w.y[0] * sum_x + w.y[1] * sum_y + w.y[2] * sum) * inv_p;
        vg = (w.fx < 0 ? fb2 : vd * w.fx * inv_p2) + (w.fy < 0 ? fb2 : vd * w.fy * inv_p2);
      }
      // The outward normal -(gx, gy, 1) / |(gx, gy, 1)|, with one division.
      const double scale = -1.0 / std::sqrt(gx * gx + gy * gy + 1.0);
      const Vec3d n_pad(gx * scale, gy * scale, scale);
      make(out, T, sn, e.x * p, e.y * p, depth, n_pad, var_depth, vg, e.pressure, time);
    }
    return active_count_;
  }

  // The refined correction of an active tactel's depth at fitted depth f (the model above,
  // step 1): d = measured - sigma lambda(a) + jensen lambda''(a), a = (t - f) / sigma, by
  // linear interpolation in the tables (a clamped to their range; f itself is not clamped at
  // 0: the fit's noise is symmetric, a clamp would bias it). Also returns a and lambda(a).
  // What it reads of the extractor is gathered once per frame into a Censoring.
  struct Refined {
    double depth, a, lambda;
  };
  struct Censoring {
    double t, inv_sigma, sigma;
    const double (*table)[4];
  };
  Censoring censoring() const { return {censor_depth_, inv_sigma_, model_.sigma_normal, lambda_}; }
  static Refined refined(const Censoring& c, const Active& e, double f) {
    const double a = (c.t - f) * c.inv_sigma;
    // (max before min, with the bound first: a NaN, which a valid model and pose never give,
    // still lands in the table rather than becoming an index out of range.)
    const double u =
        std::min(std::max(0.0, (a - kTableLow) * kTableScale), double(kTable - 1) - 1e-9);
    const int k = static_cast<int>(u);
    const double w = u - k;
    const double* row = c.table[k];
    const double lam = row[0] + w * row[2];
    const double l2 = row[1] + w * row[3];
    return {e.measured - c.sigma * lam + e.jensen * l2, a, lam};
  }
  // The refined censoring's quadric (coefficients q in pitch units) at an active tactel.
  static double fitted(const double* q, const Active& e) {
    return q[0] + e.x * (q[1] + q[3] * e.x + q[4] * e.y) + e.y * (q[2] + q[5] * e.y);
  }
  // The mean of max(q, 0) over the unit square (pitch units) about an active tactel, whose
  // centre's value is c (the model above, step 5).
  static double footprint_mean(const double* q, const Active& e, double c) {
    const double gx = q[1] + 2 * q[3] * e.x + q[4] * e.y, gy = q[2] + q[4] * e.x + 2 * q[5] * e.y;
    const double mid = c + 0.25 * (q[3] + q[5]);  // the corners' mean less their slopes' share
    if (std::min({mid + 0.5 * (gx + gy) + 0.25 * q[4], mid + 0.5 * (gx - gy) - 0.25 * q[4],
                  mid + 0.5 * (gy - gx) - 0.25 * q[4], mid - 0.5 * (gx + gy) + 0.25 * q[4]}) > 0) {
      return c + (q[3] + q[5]) / 12.0;
    }
    double sum = 0;
    for (int i = 0; i < 4; ++i) {
      const double v = kGaussNode[3][i];
      for (int j = 0; j < 4; ++j) {
        const double u = kGaussNode[3][j];
        const double at = c + u * (gx + q[3] * u + q[4] * v) + v * (gy + q[5] * v);
        sum += kGaussWeight[3][i] * kGaussWeight[3][j] * std::max(at, 0.0);
      }
    }
    return sum;
  }
  // An active tactel's corrected depth at its centre, for the quadric q of the centres' depths:
  // the censoring correction at its expected reading, and with tactel_area the footprint
  // excess of q removed (the model above, steps 1 and 5).
  double centre_depth(const Censoring& cens, const double* q, const Active& e) const {
    const double c = fitted(q, e);
    if (!options_.tactel_area) return refined(cens, e, c).depth;
    const double f = footprint_mean(q, e, c);
    return refined(cens, e, f).depth - (f - c);
  }

  // The refined censoring correction (the model above, step 1): quadric fit of the plug-in
  // depths, the correction evaluated at the fitted depth with its Jensen term, refitted once.
  // Leaves the plug-in depths when at most six tactels are active, the quadric is not
  // determined or it does not fit.
  template <class = void>
  void refine_censoring() {
    const double sigma = model_.sigma_normal;
    const std::size_t count = active_count_;
    if (!(sigma > 0) || count < 7) return;
    // Pass 0's normal equations, on the plug-in depths: the moments of the active tactels'
    // coordinates, and the right-hand side.
    double* ata = factor_;  // factored in place, kept for per_pad
    normal_matrix(ata);
    double sol[6];
    rhs(sol);
    double* inv_diag = factor_inv_diag_;
    if (!detail_cholesky(ata, inv_diag)) return;
    factored_ = true;
    detail_solve(ata, inv_diag, sol);
    const double vd = depth_variance();
    const double half_v_over_sigma = 0.5 * vd / sigma;
    // The corrected depth at fitted depth f (see refined()) and, when `with_variance`, its
    // variance: the truncated normal's, sigma^2 (1 - lambda'), plus the fit's share through
    // the correction's slope lambda'.
    const Censoring cens = censoring();
    const bool area = options_.tactel_area;
    const auto correct = [&](Active& e, const double* q, bool with_variance) {
      const double c = fitted(q, e);
      const double f = area ? footprint_mean(q, e, c) : c;
      const Refined r = refined(cens, e, f);
      padded_[e.at] = r.depth - (f - c);
      if (with_variance) {
        const double l1 = r.lambda * (r.lambda - r.a);
        e.var = vd * (1.0 - l1) + l1 * l1 * e.jensen * 2.0 * sigma;
      }
    };
    // The leverages r' A^-1 r (r = 1, X, Y, X^2, XY, Y^2) as one quartic in the pad
    // coordinates, whose 15 coefficients (from the entries of A^-1) are dotted with each
    // tactel's monomials.
    double bm[36];
    inverse_normal_matrix(ata, inv_diag, bm);
    const auto bb = [bm](int i, int j) { return bm[i * 6 + j]; };  // i >= j
    const double lev[16] = {bb(0, 0),
                            2 * bb(1, 0),
                            2 * bb(2, 0),
                            bb(1, 1) + 2 * bb(3, 0),
                            2 * (bb(2, 1) + bb(4, 0)),
                            bb(2, 2) + 2 * bb(5, 0),
                            2 * bb(3, 1),
                            2 * (bb(4, 1) + bb(3, 2)),
                            2 * (bb(5, 1) + bb(4, 2)),
                            2 * bb(5, 2),
                            bb(3, 3),
                            2 * bb(4, 3),
                            bb(4, 4) + 2 * bb(5, 3),
                            2 * bb(5, 4),
                            bb(5, 5),
                            0.0};
    const Eigen::Map<const Eigen::Array<double, 16, 1>> lev_map(lev);
    // With tactel_area the fit describes the readings; the centres' quadric has the same
    // curvature (the model above, step 5).
    double centres[6];
    std::copy_n(sol, 6, centres);
    if (area) centres[0] -= (sol[3] + sol[5]) / 12.0;
    // Pass 0: leverages, residuals, corrections at the first fit, pass 1's right-hand side.
    double rss = 0;
    Vec6 sum1 = Vec6::Zero();
    for (std::size_t i = 0; i < count; ++i) {
      Active& e = active_[i];
      const double* row = monomials_[e.tactel].data();
      const double h = (lev_map * Eigen::Map<const Eigen::Array<double, 16, 1>>(row)).sum();
      e.jensen = h * half_v_over_sigma;
      const double f = fitted(sol, e);
      const double res = padded_[e.at] - f;
      rss += res * res;
      correct(e, centres, false);
      const double d = padded_[e.at];
      sum1 += Eigen::Map<const Vec6>(row) * d;
    }
    if (!quadric_fits(rss, count, 3.0)) {
      // Not a quadric (an edge, a corner): back to the plug-in depths.
      for (std::size_t i = 0; i < count; ++i) {
        Active& e = active_[i];
        padded_[e.at] = e.measured - e.plug_in;
      }
      return;
    }
    refined_ = true;
    // Pass 1: the corrections at the refit.
    double sol1[6];
    Vec6::Map(sol1) = sum1;
    detail_solve(ata, inv_diag, sol1);
    // The refit gives the per-tactel normals: its gradient at (X, Y) is
    // (q1 + 2 q3 X + q4 Y, q2 + q4 X + 2 q5 Y) per pitch, with variances v e' A^-1 e for
    // e = (0, 1, 0, 2X, Y, 0) and (0, 0, 1, 0, X, 2Y): two quadratic forms in X and Y, whose
    // coefficients come from the entries of A^-1 (above), scaled to slopes per metre (only
    // their sum is used). per_tactel then evaluates the corrections at the refit itself, in
    // the same pass as the normals.
    if (options_.mode != ContactMode::per_tactel || !options_.local_normals) {
      // (Only the per-pad contact reads the corrected depths' variances; see the model,
      // step 1.)
      const bool variances = options_.mode == ContactMode::per_pad;
      for (std::size_t i = 0; i < count; ++i) {
        correct(active_[i], sol1, variances);
      }
      return;
    }
    for (int a = 0; a < 6; ++a) quad_[a] = sol1[a];
    const auto inv = [&](int i, int j) { return i >= j ? bb(i, j) : bb(j, i); };
    const double scale = vd / (model_.geometry.pitch * model_.geometry.pitch);
    const double fx[6] = {inv(1, 1),     4 * inv(1, 3), 2 * inv(1, 4),
                          4 * inv(3, 3), 4 * inv(3, 4), inv(4, 4)};
    const double fy[6] = {inv(2, 2), 2 * inv(2, 4), 4 * inv(2, 5),
                          inv(4, 4), 4 * inv(4, 5), 4 * inv(5, 5)};
    for (int a = 0; a < 6; ++a) slope_var_[a] = scale * (fx[a] + fy[a]);
    quad_ok_ = true;
  }

  // The lower triangle of B = A^-1 = L^-T L^-1 (row stride 6) from the factor of
  // detail_cholesky: L^-1 by forward substitution, then B_ij = sum over a >= i of
  // (L^-1)_ai (L^-1)_aj. (The loops test their triangular bounds inside, so that they unroll
  // in full without out-of-range iterations for the compiler to warn about.)
  static void inverse_normal_matrix(const double* l, const double* inv_diag, double* inverse) {
    double li[6][6] = {};  // li[a][k] = (L^-1)_ak, zero above the diagonal
#pragma GCC unroll 6
    for (int k = 0; k < 6; ++k) {
#pragma GCC unroll 6
      for (int a = 0; a < 6; ++a) {
        if (a < k) continue;
        double v = a == k ? 1.0 : 0.0;
#pragma GCC unroll 6
        for (int b = 0; b < 6; ++b) {
          if (b >= k && b < a) v -= l[a * 6 + b] * li[b][k];
        }
        li[a][k] = v * inv_diag[a];
      }
    }
#pragma GCC unroll 6
    for (int i = 0; i < 6; ++i) {
#pragma GCC unroll 6
      for (int j = 0; j < 6; ++j) {
        if (j > i) continue;
        double v = 0;
#pragma GCC unroll 6
        for (int a = 0; a < 6; ++a) {
          if (a >= i) v += li[a][i] * li[a][j];
        }
        inverse[i * 6 + j] = v;
      }
    }
  }

  // The lower triangle (row stride 6; the upper one is not written) of the quadric fit's
  // normal matrix over the rows 1, X, Y, X^2, XY, Y^2 of the active tactels, from the sums of
  // their monomials.
  void normal_matrix(double* a) const {
    // (Summed as one fixed-size array, which stays in vector registers.)
    Eigen::Array<double, 16, 1> m = Eigen::Array<double, 16, 1>::Zero();
    for (std::size_t i = 0; i < active_count_; ++i) {
      m += Eigen::Map<const Eigen::Array<double, 16, 1>>(monomials_[active_[i].tactel].data());
    }
    a[0] = m[0];
    a[6] = m[1], a[7] = m[3];
    a[12] = m[2], a[13] = m[4], a[14] = m[5];
    a[18] = m[3], a[19] = m[6], a[20] = m[7], a[21] = m[10];
    a[24] = m[4], a[25] = m[7], a[26] = m[8], a[27] = m[11], a[28] = m[12];
    a[30] = m[5], a[31] = m[8], a[32] = m[9], a[33] = m[12], a[34] = m[13], a[35] = m[14];
  }

  // The normal equations' right-hand side: the sum of the active tactels' rows 1, X, Y, X^2,
  // XY, Y^2 times their depths (one fixed-size array, kept in vector registers).
  using Vec6 = Eigen::Array<double, 6, 1>;
  void rhs(double* out) const {
    Vec6 sum = Vec6::Zero();
    for (std::size_t i = 0; i < active_count_; ++i) {
      sum += Eigen::Map<const Vec6>(monomials_[active_[i].tactel].data()) * padded_[active_[i].at];
    }
    Vec6::Map(out) = sum;
  }

  double q2() const { return model_.geometry.pitch * model_.geometry.pitch / 12.0; }

  template <class = void>
  std::size_t per_pad(const Eigen::Isometry3d& T, double time,
                      std::vector<Contact<double>>& out) const {
    const PadGeometry& g = model_.geometry;
    const double p = g.pitch;
    const double vd = depth_variance();
    const std::size_t count = active_count_;
    // Centroid of the active tactels, in pitch units from the pad centre (see the model above),
    // and the sum of their readings (the contact's pressure).
    double w = 0, wx = 0, wy = 0, corr2 = 0, dd = 0;  // dd: the depths' sum of squares
    for (std::size_t i = 0; i < count; ++i) {
      const Active& e = active_[i];
      w += e.pressure;
      wx += e.x;
      wy += e.y;
      corr2 += e.var - vd;
      const double d = padded_[e.at];
      dd += d * d;
    }
    const double n = static_cast<double>(count);
    const double xc = wx / n, yc = wy / n;
    // Least squares of the depths on 1, X, Y, X^2, XY, Y^2 (X, Y from the centroid). A plane
    // or a mean cannot say how the surface curves, and its value above the centroid lies below
    // a convex surface by the chord sag (E[u'Hu] / 2 over the active tactels: about -0.15 mm
    // on a 15 mm sphere under a 3.4 mm pitch pad). So when fewer than six tactels are active,
    // or they do not determine a quadric (a pivot vanishes: one or two rows), the tactels give
    // their contacts one by one.
    if (count < 6) return per_tactel(T, time, out);
    // The quadric in pad coordinates (its normal matrix factored already when the refined
    // censoring correction ran on this frame), then its value and slopes at the centroid, and
    // their variances e' A^-1 e = |L^-1 e|^2 (per unit depth variance).
    double local[36], local_inv[6];
    const double* l = factor_;
    const double* inv_l = factor_inv_diag_;
    if (!factored_) {
      normal_matrix(local);
      if (!detail_cholesky(local, local_inv)) return per_tactel(T, time, out);
      l = local;
      inv_l = local_inv;
    }
    double sol[6], ad[6];
    rhs(ad);
    std::copy_n(ad, 6, sol);
    detail_solve(l, inv_l, sol);
    // A quadric that does not fit the depths at all (a patch too wide for a quadric to follow
    // the surface, as across a torus's tube) puts the contact off the surface (+0.11 mm on
    // average on a torus R40 r15, against +0.001 mm where the quadric fits): the tactels then
    // give their contacts one by one, as when no quadric is determined. The test is the
    // refined correction's at 7 rather than 3 standard deviations: a frame refused there
    // trades its one contact for one per tactel, all sharing the frame's pose error, and the
    // quadric's residuals on a smooth surface are not the depth noise alone (at 3, 1.6 % of
    // the frames on a 40 mm sphere were refused, and every shape's clouds got worse). A
    // noiseless model (sigma_normal = 0) is not tested: its quantisation alone would refuse
    // every curved patch.
    // (The residuals' sum of squares is the depths' less the fit's, d'd - sol' A'd.)
    if (count > 6 && model_.sigma_normal > 0) {
      double rss = dd;
      for (int a = 0; a < 6; ++a) rss -= sol[a] * ad[a];
      if (!quadric_fits(rss, count, 7.0)) return per_tactel(T, time, out);
    }
    // The row at the centroid, and its derivatives along X and Y.
    double e0[6] = {1.0, xc, yc, xc * xc, xc * yc, yc * yc};
    double ex[6] = {0.0, 1.0, 0.0, 2.0 * xc, yc, 0.0};
    double ey[6] = {0.0, 0.0, 1.0, 0.0, xc, 2.0 * yc};
    double fit[3] = {}, inv_diag[3];
    int k = 0;
    for (double* e : {e0, ex, ey}) {
      for (int a = 0; a < 6; ++a) fit[k] += e[a] * sol[a];
      inv_diag[k++] = detail_forward_norm2(l, inv_l, e);
    }
    const double fb = options_.fallback_normal_sigma;
    double gx = 0, gy = 0, slope_var = 2.0 * fb * fb;  // unmeasured: the pad's normal
    if (options_.local_normals) {
      gx = fit[1] / p;
      gy = fit[2] / p;
      slope_var = vd * (inv_diag[1] + inv_diag[2]) / (p * p);
    }
    const Vec3d n_pad = -Vec3d(gx, gy, 1.0).normalized();
    const double var_a = vd * inv_diag[0] + std::max(corr2, 0.0) / (n * n);
    make(out, T, shared_noise(), xc * p, yc * p, fit[0], n_pad, var_a, slope_var, w, time);
    return 1;
  }

  // Whether a quadric fitted to the depths of `count` > 6 active tactels fits them: a
  // chi-square test of the residuals' sum of squares `rss` [m^2] at `sigmas` standard
  // deviations of its sum, with the depth variance of a reading.
  bool quadric_fits(double rss, std::size_t count, double sigmas) const {
    const double dof = static_cast<double>(count) - 6.0;
    return rss <= depth_variance() * (dof + sigmas * std::sqrt(2.0 * dof));
  }

  // The quadric fits' 6 x 6 linear algebra (row stride 6), with every loop unrolled in full.
  static constexpr int kQuad = 6;
  // In-place Cholesky factor (lower triangle) of a normal matrix, and the reciprocals of its
  // diagonal; false when a pivot is not positive relative to its diagonal entry.
  static bool detail_cholesky(double* a, double* inv_diag) {
#pragma GCC unroll 6
    for (int j = 0; j < kQuad; ++j) {
      double djj = a[j * 6 + j];
#pragma GCC unroll 6
      for (int k = 0; k < j; ++k) djj -= a[j * 6 + k] * a[j * 6 + k];
      if (!(djj > 1e-10 * a[j * 6 + j])) return false;
      const double ljj = std::sqrt(djj);
      a[j * 6 + j] = ljj;
      inv_diag[j] = 1.0 / ljj;
#pragma GCC unroll 6
      for (int i = j + 1; i < kQuad; ++i) {
        double v = a[i * 6 + j];
#pragma GCC unroll 6
        for (int k = 0; k < j; ++k) v -= a[i * 6 + k] * a[j * 6 + k];
        a[i * 6 + j] = v * inv_diag[j];
      }
    }
    return true;
  }
  // Solves L L' x = b in place with the factor of detail_cholesky.
  static void detail_solve(const double* l, const double* inv_diag, double* b) {
#pragma GCC unroll 6
    for (int i = 0; i < kQuad; ++i) {
#pragma GCC unroll 6
      for (int k = 0; k < i; ++k) b[i] -= l[i * 6 + k] * b[k];
      b[i] *= inv_diag[i];
    }
#pragma GCC unroll 6
    for (int i = kQuad - 1; i >= 0; --i) {
#pragma GCC unroll 6
      for (int k = i + 1; k < kQuad; ++k) b[i] -= l[k * 6 + i] * b[k];
      b[i] *= inv_diag[i];
    }
  }

  // |L^-1 e|^2 by forward substitution with the factor of detail_cholesky; overwrites e.
  static double detail_forward_norm2(const double* l, const double* inv_diag, double* e) {
    double s = 0;
#pragma GCC unroll 6
    for (int i = 0; i < kQuad; ++i) {
#pragma GCC unroll 6
      for (int k = 0; k < i; ++k) e[i] -= l[i * 6 + k] * e[k];
      e[i] *= inv_diag[i];
      s += e[i] * e[i];
    }
    return s;
  }

  SensorModel model_;
  ContactOptions options_;
  std::vector<double> bias_;  // truncation bias by reading count [m]
  // The depth [m] at which readings are censored (the threshold count less half a count), and
  // 1 / sigma_normal [1/m] (0 for a noiseless pad, which is not corrected).
  double censor_depth_ = 0.0, inv_sigma_ = 0.0;
  // Per tactel: 1, X, Y, X^2, XY, Y^2, X^3, X^2 Y, X Y^2, Y^3, X^4, X^3 Y, X^2 Y^2, X Y^3, Y^4
  // (X, Y its pad coordinates in pitch units) and a zero: the normal matrix of a quadric fit is
  // a sum of these.
  std::vector<std::array<double, 16>> monomials_;
  std::vector<Active> active_;         // the first active_count_ are this frame's, row-major
  std::vector<std::uint32_t> listed_;  // extract's workspace: indices of the active tactels
  std::vector<std::size_t> cell_;      // per tactel, its cell in the padded grid
  std::size_t active_count_ = 0;
  // The Cholesky factor of this frame's quadric normal matrix, when the refined correction
  // made it (factored_).
  double factor_[36] = {}, factor_inv_diag_[6] = {};
  bool factored_ = false;
  // The refined censoring's quadric (coefficients of 1, X, Y, X^2, XY, Y^2 in pitch units),
  // when it fitted this frame (quad_ok_: the per-tactel contacts then take their corrected
  // depths and normals from it), and the sum of its two slope variances as a quadratic form
  // in X and Y (coefficients of 1, X, Y, X^2, XY, Y^2).
  double quad_[6] = {}, slope_var_[6] = {};
  bool quad_ok_ = false;
  bool refined_ = false;  // the refined censoring correction applied to this frame
  // The corrected depths [m] (0 where inactive) and active flags of the pad with a border of
  // inactive tactels, (rows + 2) x (cols + 2).
  std::vector<double> padded_;
  std::vector<unsigned char> on_;

  // The plane fit of step 2 for one pattern of active neighbours (bit 3 (dr + 1) + (dc + 1) of
  // the 3x3 neighbourhood, the centre always set). With S, S_x and S_y the sums of the active
  // depths, and of them times dc and dr, the slopes in pitch units are x . (S_x, S_y, S) and
  // y . (S_x, S_y, S), and their variances (depth variance) * f / pitch^2, f < 0 meaning not
  // measured (the fallback variance). 64 bytes a pattern, 32 KiB in all.
  struct PlaneWeights {
    double x[3], y[3];
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
        // Centred: c_xd = S_x - mx S, c_yd = S_y - my S; the slopes solve C g = (c_xd, c_yd).
        const double mx = sx / n, my = sy / n;
        const double cxx = sxx - sx * mx, cyy = syy - sy * my, cxy = sxy - sx * my;
        const double det = cxx * cyy - cxy * cxy;
        constexpr double kTiny = 1e-9;
        double ax = 0, bx = 0, ay = 0, by = 0;  // g_x = ax c_xd + bx c_yd, g_y = ay c_xd + by c_yd
        if (cxx > kTiny && cyy > kTiny && det > 0.1 * cxx * cyy) {
          ax = cyy / det;
          bx = -cxy / det;
          ay = -cxy / det;
          by = cxx / det;
          w.fx = cyy / det;
          w.fy = cxx / det;
        } else if (cxx > kTiny && std::abs(cxy) <= kTiny) {  // a row: x slope only
          ax = 1.0 / cxx;
          w.fx = 1.0 / cxx;
        } else if (cyy > kTiny && std::abs(cxy) <= kTiny) {  // a column: y slope only
          by = 1.0 / cyy;
          w.fy = 1.0 / cyy;
        }
        w.x[0] = ax;
        w.x[1] = bx;
        w.x[2] = -(ax * mx + bx * my);
        w.y[0] = ay;
        w.y[1] = by;
        w.y[2] = -(ay * mx + by * my);
      }
      return t;
    }();
    return table;
  }
  // For each mask of eight lanes, the indices of its set lanes in order, and their count.
  struct Lanes {
    std::uint8_t index[8];
    std::uint8_t count;
  };
  static const std::array<Lanes, 256>& active_lanes() {
    static constexpr std::array<Lanes, 256> table = [] {
      std::array<Lanes, 256> t{};
      for (unsigned mask = 0; mask < 256; ++mask) {
        for (std::uint8_t lane = 0; lane < 8; ++lane) {
          if (mask >> lane & 1u) t[mask].index[t[mask].count++] = lane;
        }
      }
      return t;
    }();
    return table;
  }
  // lambda and lambda'' tabulated at a = kTableLow + i / kTableScale, and their differences
  // to the next entry (zero at the last).
  static constexpr int kTable = 641;  // a in [-12, 8]
  static constexpr double kTableLow = -12.0, kTableScale = 32.0;
  alignas(32) double lambda_[kTable][4] = {};
};

}  // namespace taxel::sensor
