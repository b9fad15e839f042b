// SPDX-License-Identifier: MIT
// Surfel: a Kalman point that knows it sits on a curved surface.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "taxel/core/contact.hpp"
#include "taxel/fusion/kalman.hpp"

namespace taxel::fusion {

/// Fuses contacts into a surface point, one contact at a time, like `Kalman`, but without the
/// bias a static 3-D state has on a curved surface.
///
/// Why. A fused point gathers contacts from a patch as wide as the association gate. On a
/// surface of curvature H, a contact at a sideways offset u from the point lies u'Hu/2 below
/// the point's tangent plane (the sag) and its normal is turned by about Hu. Averaging
/// positions lands the point inside the surface by E[u'Hu]/2 (chord sag). A Kalman filter
/// fed covariances whose tight axis follows each contact's own normal lands outside by about
/// (1 - 2 s_n^2/s_t^2) E[u'Hu]/2: each tight plane is the tangent plane at its own contact,
/// and tangent planes of a convex patch meet outside it.
///
/// What. The point keeps a Kalman filter on its position, a tangent frame (normal n0 from its
/// first contact with a normal, origin at its first contact) and, for every contact whose
/// normal lies within `max_normal_angle` of the point's mean normal:
///  - the contact's covariance is turned onto the point's mean normal (Rodrigues rotation
///    taking the contact normal to it), so all tight planes are parallel and the filter's mean
///    is an information-weighted average in that frame, whose only bias is the sag;
///  - its sideways offset u (in the frame) and its normal's slope s (sideways part over
///    normal part, which is H u + const on a quadric) are accumulated, 19 sums in all;
///  - the curvature H is the symmetric part of the least-squares fit of s on u, with a ridge
///    prior H ~ N(0, curvature_prior^2) against normal noise `normal_sigma`, so that few or
///    collinear contacts give H near 0; a contact whose normal states a larger uncertainty
///    (`Contact::normal_sigma`, sigma_c > normal_sigma: a normal the sensor guessed rather than
///    measured) enters the fit with its slope weighted down by (normal_sigma / sigma_c)^2, and
///    its position in full;
///  - the mean is the quadric's point above the weighted centroid of the offsets: the
///    weighted mean height plus the sag tr(H C_uu) / 2 (C_uu the weighted covariance of the
///    offsets), the sag bounded by half the offsets' spread so that a noisy fit cannot throw
///    the point off the surface.
/// Contacts without a normal, or turned further than `max_normal_angle` from the mean normal or
/// from n0 (another face across an edge, or an outlier), are apart from the patch: they update
/// the filter unturned, enter no sum, and are kept in J_x and eta_x (the information and
/// information vector they brought). While they are at most half of the point's contacts the
/// mean is the patch's point d. Beyond that the patch, anchored at the point's first contact,
/// holds the minority (a point started on one face whose gate then reaches mostly across the
/// edge, where its few patch contacts place it beyond the edge), and the mean moves towards
/// the fusion of d, with the patch's information J - J_x, and the apart contacts:
/// J^-1 ((J - J_x) d + eta_x), Kalman's tight planes meeting across the crease; fully at 80 %.
/// (Fusing them at every share measured worse: on a box and a cone one face's lateral
/// information is another's height information, and pulls a point on the crease inside.)
/// With three or more apart contacts the point is, besides, kept from lying outside their
/// plane: through their Kalman mean, along the mean of their normals that state no more noise
/// than twice `normal_sigma` (a guessed normal defines no plane). A point whose patch contacts
/// scattered past a convex edge would otherwise sit on its face's plane beyond the edge.
/// A crease shallower than `max_normal_angle` (or one a depth-map normal rounds) puts every
/// contact in the patch, and the slopes jump across it where a quadric has them change
/// linearly. Where the slopes' residual about the fitted H exceeds 9 times the variance the
/// normals state, the mean moves towards plain Kalman's (every contact unturned, J_k and
/// eta_k), fully at 25 times (`crease_share`). With sharp normals this changes little; with
/// normals that round a box's edges it brings Surfel level with Kalman there.
/// On a plane with exact normals (all equal) the rotation is the identity and H = 0: the
/// result is `Kalman`'s, up to rounding.
/// The offsets are measured positions: their own noise is not removed from M (the contacts
/// a point gathers are those whose noisy positions fall near it, a Berkson error model, so
/// an errors-in-variables correction would overcorrect). A contact's position may itself have
/// strayed along the tangent plane (a pose error, a camera's noise): such scatter lifts it off
/// a curved surface by u'Hu / 2, tr(H Sigma_t) / 2 on average (sigma_t^2 / R on a sphere),
/// and the mean subtracts that lift for the scatter the contacts state, which is their
/// covariance across the normal less their footprint (`Contact::footprint_sigma`). A footprint
/// (a tactel read at its centre) is where on the surface a contact stands for; its position
/// lies on the surface and is not lifted.
///
/// The filter is `Kalman`'s (same `Config::kalman`: process noise, gate, P0) kept in
/// information form, J = P^-1 and eta = J (mu - origin): without process noise or gate an
/// update is two sums, J += R^-1 and eta += R^-1 (m - origin), and the rotation turns R^-1,
/// which does not depend on the state. P = J^-1 is formed when asked for (`covariance`), and
/// in each update only with process noise or a gate. A covariance whose inverse overflows
/// (a variance below about 1e-308 m^2) makes the point non-finite, and `ContactCloud` refuses
/// the contact. State: 600 bytes (double). No allocation.
template <Scalar S>
struct Surfel {
  /// The floating-point type of positions and covariances (float or double).
  using Scalar = S;
  /// Configuration; defaults suit tactile pads of a few millimetres pitch.
  struct Config {
    typename Kalman<S>::Config kalman{};  ///< process noise, gate and P0 of the filter
    S max_normal_angle =
        S(1.2);  ///< contacts turned further [rad] are not curvature data, in (0, pi/2)
    S normal_sigma = S(0.05);  ///< noise of a contact normal [rad], in [1e-6, pi]
    /// Prior standard deviation of the curvature [1/m], in [1e-6, 1e9].
    S curvature_prior = S(100);
  };
  /// A fused point: the filter in information form, its tangent frame and the curvature sums.
  /// Every member starts at zero (Eigen's vectors would otherwise start uninitialised, even in
  /// `State s{}`).
  struct State {
    Vec3<S> origin = Vec3<S>::Zero();  ///< the first contact's position [m]: origin of the
                                       ///< filter and the frame
    S info[6] = {};                    ///< filter information J = P^-1 (xx, xy, xz, yy, yz, zz)
                                       ///< [1/m^2]
    Vec3<S> eta = Vec3<S>::Zero();     ///< information vector J (mu - origin), mu the filter
                                       ///< mean [1/m]
    Vec3<S> n0 = Vec3<S>::Zero();  ///< frame normal (zero until a contact with a normal arrives)
    Vec3<S> t1 = Vec3<S>::Zero();  ///< first tangent of the frame
    Vec3<S> t2 = Vec3<S>::Zero();  ///< second tangent of the frame, n0 x t1
    Vec3<S> normal_sum = Vec3<S>::Zero();   ///< sum of the accepted contact normals
    Vec3<S> unit_normal = Vec3<S>::Zero();  ///< normal_sum / |normal_sum| (zero until a
                                            ///< contact with a normal)
    S count = S(0);                         ///< contacts in the sums
    S weight = S(0);  ///< sum of their weights w (information along the normal) [1/m^2]
    S sz = S(0);      ///< w-weighted sum of the heights z along n0 [m]
    S su[2] = {};     ///< w-weighted sum of u [m]
    S suu[3] = {};    ///< w-weighted sums of u_x^2, u_x u_y, u_y^2 [m^2]
    // The curvature fit's sums, weighted by v = w k (k <= 1 the slope's share, see share()).
    S vweight = S(0);  ///< sum of v [1/m^2]
    S vu[2] = {};      ///< v-weighted sum of u [m]
    S ss[2] = {};      ///< v-weighted sum of s [-]
    S vuu[3] = {};     ///< v-weighted sums of u_x^2, u_x u_y, u_y^2 [m^2]
    S ssu[4] = {};     ///< v-weighted sums of s_x u_x, s_x u_y, s_y u_x, s_y u_y [m]
    /// w-weighted sums of the stated scatter across the normal in the frame (xx, xy, yy)
    /// [m^2]: the covariance there less the footprint (`Contact::footprint_sigma`).
    S scov[3] = {};
    /// Information J_x [1/m^2] and information vector eta_x [1/m] of the contacts apart from
    /// the patch (without a normal, or turned further than max_normal_angle), which the filter
    /// took unturned.
    S xinfo[6] = {};
    Vec3<S> xeta = Vec3<S>::Zero();  ///< see xinfo
    S xcount = S(0);                 ///< contacts apart from the patch
    /// sum of their normals that state no more noise than twice normal_sigma
    Vec3<S> xnormal = Vec3<S>::Zero();
    S sss[3] = {};  ///< v-weighted sums of s_x^2, s_x s_y, s_y^2 [-]
    /// Information [1/m^2] and information vector [1/m] of every contact unturned: plain
    /// Kalman's, which the mean moves to where one smooth patch does not fit the slopes.
    S kinfo[6] = {};
    Vec3<S> keta = Vec3<S>::Zero();  ///< see kinfo
  };
  /// Calls f(values, count) on each part of a state, in a fixed order: what a state is made
  /// of, for saving and restoring a cloud (ContactCloud::restore).
  template <class Fn>
  static void for_each_field(State& s, Fn&& f) {
    for (Vec3<S>* v : {&s.origin, &s.eta, &s.n0, &s.t1, &s.t2, &s.normal_sum, &s.unit_normal}) {
      f(v->data(), 3);
    }
    f(s.info, 6);
    f(&s.count, 1);
    f(&s.weight, 1);
    f(&s.sz, 1);
    f(s.su, 2);
    f(s.suu, 3);
    f(&s.vweight, 1);
    f(s.vu, 2);
    f(s.ss, 2);
    f(s.vuu, 3);
    f(s.ssu, 4);
    f(s.scov, 3);
    f(s.xinfo, 6);
    f(s.xeta.data(), 3);
    f(&s.xcount, 1);
    f(s.xnormal.data(), 3);
    f(s.sss, 3);
    f(s.kinfo, 6);
    f(s.keta.data(), 3);
  }
  static constexpr bool kMerges =
      true;  ///< Contacts fuse into points (FusionPolicy; false only for Raw).

  Surfel() = default;
  /// Throws std::invalid_argument naming the field that is out of range.
  explicit Surfel(const Config& config) : config_(config) {
    (void)Kalman<S>(config.kalman);  // validates the filter's part, naming the field
    if (!(config.max_normal_angle > S(0)) || !(config.max_normal_angle < S(1.5707963267948966))) {
      throw std::invalid_argument("Surfel::Config::max_normal_angle must be in (0, pi/2), got " +
                                  std::to_string(config.max_normal_angle));
    }
    // (Bounded so that the ridge (normal_sigma / curvature_prior)^2 stays a finite, normal
    // number in float too: a curvature prior of 1e-250 / m made it infinite, and the fitted
    // normal NaN.)
    if (!(config.normal_sigma >= S(1e-6)) || !(config.normal_sigma <= S(3.141592653589793))) {
      throw std::invalid_argument("Surfel::Config::normal_sigma must be in [1e-6, pi] rad, got " +
                                  std::to_string(config.normal_sigma));
    }
    if (!(config.curvature_prior >= S(1e-6)) || !(config.curvature_prior <= S(1e9))) {
      throw std::invalid_argument(
          "Surfel::Config::curvature_prior must be in [1e-6, 1e9] 1/m, got " +
          std::to_string(config.curvature_prior));
    }
    cos_max_ = std::cos(config.max_normal_angle);
    q2_ = config.kalman.process_noise * config.kalman.process_noise;
    ridge_ = config.normal_sigma * config.normal_sigma /
             (config.curvature_prior * config.curvature_prior);
  }

  /// A point at the contact; its frame starts here when the contact has a normal.
  State init(const Contact<S>& c) const {
    State s{};
    s.origin = c.position;
    if (config_.kalman.initial_sigma) {
      const S v = S(1) / (*config_.kalman.initial_sigma * *config_.kalman.initial_sigma);
      s.info[0] = s.info[3] = s.info[5] = v;
    } else {
      inverse(c.covariance, s.info);
    }
    for (int i = 0; i < 6; ++i) s.kinfo[i] = s.info[i];
    if (c.normal) {
      start_frame(s, c);
    } else {
      for (int i = 0; i < 6; ++i) s.xinfo[i] = s.info[i];
      s.xcount = S(1);
    }
    return s;
  }

  /// One update; false (state untouched) when the Mahalanobis gate refuses the contact.
  bool fuse(State& s, const Contact<S>& c, std::uint32_t) const {
    S ci[6];  // the contact's information R^-1: it does not depend on the state
    inverse(c.covariance, ci);
    const Vec3<S> d = c.position - s.origin;  // the offset from the point's origin
    if (!fuse_patch(s, c, d, ci)) return false;
    for (int i = 0; i < 6; ++i) s.kinfo[i] += ci[i];
    s.keta += times(ci, d);
    return true;
  }

 private:
  // The update of everything but plain Kalman's pair (kinfo, keta).
  bool fuse_patch(State& s, const Contact<S>& c, const Vec3<S>& d, const S ci[6]) const {
    if (!c.normal) return filter_apart(s, d, ci);
    if (s.count == S(0)) {
      if (!filter(s, d, ci)) return false;
      start_frame(s, c);
      return true;
    }
    const Vec3<S>& nc = *c.normal;
    const Vec3<S>& nm = s.unit_normal;
    const S cos_c = nc.dot(nm);
    // A slope is tan of the normal's angle to n0: beyond max_normal_angle (from the mean normal
    // or from n0) it is no curvature datum but another face across an edge, or an outlier.
    const S nz = nc.dot(s.n0);
    if (!(cos_c >= cos_max_) || !(nz >= cos_max_)) {
      if (!filter_apart(s, d, ci)) return false;
      if (!(c.normal_sigma > S(2) * config_.normal_sigma)) s.xnormal += nc;  // measured
      return true;
    }
    // Turn the information onto the mean normal: Q R^-1 Q' with Q = I + [v]x + [v]x^2 / (1 + c),
    // v = nc x nm, [v]x^2 = v v' - |v|^2 I written out; only the upper triangle is formed (it
    // is symmetric by construction).
    const Vec3<S> v = nc.cross(nm);
    const S k = S(1) / (S(1) + cos_c);
    const S diag = S(1) - k * v.squaredNorm();
    Mat3<S> q;
    q << diag + k * v.x() * v.x(), k * v.x() * v.y() - v.z(), k * v.x() * v.z() + v.y(),
        k * v.y() * v.x() + v.z(), diag + k * v.y() * v.y(), k * v.y() * v.z() - v.x(),
        k * v.z() * v.x() - v.y(), k * v.z() * v.y() + v.x(), diag + k * v.z() * v.z();
    const Mat3<S> qc = q * symmetric(ci);
    S turned[6];
    for (int i = 0, at = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j) turned[at++] = qc.row(i).dot(q.row(j));
    }
    if (!filter(s, d, turned)) return false;
    // Curvature sums in the frame of the first contact.
    const S ux = s.t1.dot(d), uy = s.t2.dot(d);
    const S inv_nz = S(1) / nz;
    const S sx = s.t1.dot(nc) * inv_nz, sy = s.t2.dot(nc) * inv_nz;
    // Weighted like the filter along the normal, by the contact's information there: the
    // variance along nm of the turned covariance is nc' R nc.
    const S w = S(1) / nc.dot(c.covariance * nc);
    s.normal_sum += nc;
    s.unit_normal = s.normal_sum * (S(1) / std::sqrt(s.normal_sum.squaredNorm()));
    s.count += S(1);
    add_sums(s, w, share(c), ux, uy, s.n0.dot(d), sx, sy);
    add_scatter(s, w, c);
    return true;
  }

 public:
  /// The surface point [m]: the point of the quadric fitted to the contacts above their
  /// weighted centroid in the tangent plane (`filter_mean` until a contact with a normal
  /// arrives).
  Vec3<S> mean(const State& s) const noexcept {
    if (s.count < S(1)) return filter_mean(s);
    const S inv = S(1) / s.weight;
    const S ux = s.su[0] * inv, uy = s.su[1] * inv;
    S h[3];
    fit_curvature(s, h);
    // Height of the quadric z(u) = z0 + g'u - u'Hu/2 at the centroid: the mean height plus the
    // sag tr(H C_uu) / 2.
    const S cxx = s.suu[0] * inv - ux * ux, cxy = s.suu[1] * inv - ux * uy;
    const S cyy = s.suu[2] * inv - uy * uy;
    // The sag is bounded by half the lateral spread (|H| sigma_u <= 1: a height field whose
    // slope over one standard deviation of the offsets stays below 45 degrees); beyond that the
    // fit is noise, not a surface.
    S sag = S(0.5) * (h[0] * cxx + S(2) * h[1] * cxy + h[2] * cyy);
    // Less the lift of the stated tangent-plane scatter, tr(H Sigma_t) / 2 (see the class
    // comment).
    sag -= S(0.5) * inv * (h[0] * s.scov[0] + S(2) * h[1] * s.scov[1] + h[2] * s.scov[2]);
    const S bound2 = S(0.25) * std::max(cxx + cyy, S(0));
    if (!(sag * sag <= bound2)) sag = std::copysign(std::sqrt(bound2), sag);  // rare: no sqrt
    const S z = s.sz * inv + sag;
    Vec3<S> d = ux * s.t1 + uy * s.t2 + z * s.n0;
    const S apart = s.xcount / (s.xcount + s.count);
    if (apart > kApartLow) {
      // The patch holds the minority of the point's contacts: move towards the fusion of the
      // patch's point, with the patch's information J - J_x, and the contacts apart from it,
      // J^-1 ((J - J_x) d + eta_x), fully where they are kApartHigh of the contacts.
      S ja[6], p[6];
      for (int i = 0; i < 6; ++i) ja[i] = s.info[i] - s.xinfo[i];
      inverse(s.info, p);
      const S f = std::min((apart - kApartLow) / (kApartHigh - kApartLow), S(1));
      d += f * (times(p, times(ja, d) + s.xeta) - d);
    }
    if (s.xcount >= S(3) && s.xnormal.squaredNorm() > S(0)) {
      // Not outside the other faces' plane: their Kalman mean m_x, their mean normal n_x.
      S p[6];
      inverse(s.xinfo, p);
      const Vec3<S> nx = s.xnormal.normalized();
      const S outside = nx.dot(d - times(p, s.xeta));
      if (outside > S(0)) d -= outside * nx;
    }
    const S k = crease_share(s, h);
    if (k > S(0)) {
      S p[6];
      inverse(s.kinfo, p);
      d += k * (times(p, s.keta) - d);
    }
    return s.origin + d;
  }
  /// How far the mean moves towards plain Kalman's, in [0, 1], given the fitted curvature h
  /// (`fit_curvature`): the residual of the slopes about h, per slope and weighted as the fit
  /// weighs them, over the variance the normals state (normal_sigma^2, or a contact's larger
  /// sigma_c^2); 0 up to kCreaseLow times, 1 from kCreaseHigh times, linear between. 0 with
  /// fewer than six contacts in the sums.
  S crease_share(const State& s, const S h[3]) const noexcept {
    if (s.count < S(6) || !(s.vweight >= std::numeric_limits<S>::min())) return S(0);
    const S inv = S(1) / s.vweight;
    const S ux = s.vu[0] * inv, uy = s.vu[1] * inv, sx = s.ss[0] * inv, sy = s.ss[1] * inv;
    const S cuu[3] = {s.vuu[0] * inv - ux * ux, s.vuu[1] * inv - ux * uy, s.vuu[2] * inv - uy * uy};
    const S css[3] = {s.sss[0] * inv - sx * sx, s.sss[1] * inv - sx * sy, s.sss[2] * inv - sy * sy};
    const S csu[4] = {s.ssu[0] * inv - sx * ux, s.ssu[1] * inv - sx * uy, s.ssu[2] * inv - sy * ux,
                      s.ssu[3] * inv - sy * uy};
    // The residual covariance of s - H u: C_ss - 2 H C_us + H C_uu H; half its trace.
    const S hc = h[0] * csu[0] + h[1] * (csu[1] + csu[2]) + h[2] * csu[3];
    const S hh0 = h[0] * h[0] + h[1] * h[1], hh1 = h[0] * h[1] + h[1] * h[2];
    const S hh2 = h[1] * h[1] + h[2] * h[2];
    const S hch = hh0 * cuu[0] + S(2) * hh1 * cuu[1] + hh2 * cuu[2];
    const S r2 = S(0.5) * (css[0] + css[2] - S(2) * hc + hch);
    const S stated = config_.normal_sigma * config_.normal_sigma * s.weight * inv;
    return std::clamp((r2 / stated - kCreaseLow) / (kCreaseHigh - kCreaseLow), S(0), S(1));
  }
  /// The bounds of `crease_share`, in multiples of the stated slope variance.
  static constexpr S kCreaseLow = S(9);
  static constexpr S kCreaseHigh = S(25);  ///< see kCreaseLow
  /// Shares of a point's contacts apart from its patch between which its mean moves from
  /// the patch's point to the fusion with them (see the class comment).
  static constexpr S kApartLow = S(0.5);
  static constexpr S kApartHigh = S(0.8);  ///< see kApartLow
  /// The point's surface normal (unit): the normal of the fitted quadric at the point `mean`
  /// reports, from the contacts' slopes as the curvature fit weighs them, or zero when no
  /// contact had a normal. The slope there is s(c) = s_mean + H (c - u_mean) (c the weighted
  /// centroid of the offsets, u_mean and s_mean the fit's weighted means), and the normal is
  /// n0 + s_x t1 + s_y t2, normalised. Unlike the plain mean of the contacts' normals (the
  /// gate's reference), it is the normal at the reported point rather than at the contacts'
  /// unweighted centroid, and a guessed normal counts only by its slope's share. Where the
  /// slopes' total weight is below the smallest normal number (every contact stated so large a
  /// normal_sigma, around 1e150 rad, that its share underflowed), it is the plain mean.
  Vec3<S> normal(const State& s) const noexcept {
    if (s.count < S(1)) return Vec3<S>::Zero();
    if (!(s.vweight >= std::numeric_limits<S>::min())) return s.unit_normal;
    S h[3];
    fit_curvature(s, h);
    const S inv = S(1) / s.vweight, inv_w = S(1) / s.weight;
    const S dx = s.su[0] * inv_w - s.vu[0] * inv, dy = s.su[1] * inv_w - s.vu[1] * inv;
    const S sx = s.ss[0] * inv + h[0] * dx + h[1] * dy;
    const S sy = s.ss[1] * inv + h[1] * dx + h[2] * dy;
    return (s.n0 + sx * s.t1 + sy * s.t2).normalized();
  }
  /// The filter covariance P = J^-1 [m^2] (the sag term adds no variance).
  Mat3<S> covariance(const State& s) const noexcept {
    S p[6];
    inverse(s.info, p);
    return symmetric(p);
  }
  /// The filter mean [m]: the Kalman mean of every contact the point absorbed, with the
  /// covariances of those that entered the sums turned onto the point's normal (`mean` until a
  /// contact has a normal).
  Vec3<S> filter_mean(const State& s) const noexcept {
    S p[6];
    inverse(s.info, p);
    return s.origin + times(p, s.eta);
  }

  /// The fitted curvature (H_xx, H_xy, H_yy) [1/m] in the point's tangent frame; zeros with
  /// fewer than three contacts in the sums.
  void fit_curvature(const State& s, S h[3]) const noexcept {
    h[0] = h[1] = h[2] = S(0);
    if (s.count < S(3)) return;
    const S inv = S(1) / s.vweight;
    const S ux = s.vu[0] * inv, uy = s.vu[1] * inv, sx = s.ss[0] * inv, sy = s.ss[1] * inv;
    // The ridge against the fit's total slope information: count / normal_sigma^2 when every
    // slope has the default noise, less as stated slopes are noisier (weight / vweight).
    const S lambda = ridge_ / s.count * s.weight * inv;
    const S a = s.vuu[0] * inv - ux * ux + lambda, b = s.vuu[1] * inv - ux * uy;
    const S d = s.vuu[2] * inv - uy * uy + lambda;
    const S det = a * d - b * b;
    if (!(det > S(0))) return;
    // C_su (C_uu + lambda I)^-1, rows s_x, s_y; its symmetric part.
    const S cxx = s.ssu[0] * inv - sx * ux, cxy = s.ssu[1] * inv - sx * uy;
    const S cyx = s.ssu[2] * inv - sy * ux, cyy = s.ssu[3] * inv - sy * uy;
    const S inv_det = S(1) / det;
    h[0] = (cxx * d - cxy * b) * inv_det;
    h[1] = S(0.5) * ((cxy * a - cxx * b) + (cyx * d - cyy * b)) * inv_det;
    h[2] = (cyy * a - cyx * b) * inv_det;
  }

 private:
  // The frame starts at the first contact with a normal (its offset from the origin is
  // the frame's first datum).
  void start_frame(State& s, const Contact<S>& c) const {
    s.n0 = *c.normal;
    s.t1 = s.n0.unitOrthogonal();
    s.t2 = s.n0.cross(s.t1);
    s.normal_sum = s.n0;
    s.unit_normal = s.n0;
    s.count = S(1);
    const Vec3<S> d = c.position - s.origin;
    const S w = S(1) / s.n0.dot(c.covariance * s.n0);
    add_sums(s, w, share(c), s.t1.dot(d), s.t2.dot(d), s.n0.dot(d), S(0), S(0));
    add_scatter(s, w, c);
  }
  // The stated scatter across the normal, in the frame: the covariance there less the
  // footprint's f^2 I, which is at most its smallest eigenvalue (a footprint stated wider than
  // the covariance leaves no scatter along that axis rather than a negative one).
  void add_scatter(State& s, S w, const Contact<S>& c) const {
    const Vec3<S> c1 = c.covariance * s.t1, c2 = c.covariance * s.t2;
    const S a = s.t1.dot(c1), b = s.t1.dot(c2), d = s.t2.dot(c2);
    S f2 = c.footprint_sigma * c.footprint_sigma;
    if (f2 > std::min(a, d) - std::abs(b)) {  // beyond the Gershgorin bound: the eigenvalue
      const S half = S(0.5) * (a - d);
      f2 = std::min(f2, std::max(S(0.5) * (a + d) - std::sqrt(half * half + b * b), S(0)));
    }
    s.scov[0] += w * (a - f2);
    s.scov[1] += w * b;
    s.scov[2] += w * (d - f2);
  }
  // The filter's update with the information ri = R^-1 (upper triangle) of a contact at
  // offset d = m - origin: a Kalman filter with identity models in information form,
  //   predict (q > 0 only): P- = J^-1 + q^2 I, J- = (P-)^-1, eta- = J- mu;
  //   update:               J += R^-1, eta += R^-1 (m - origin).
  // With q = 0 and no gate the update is two sums: no inverse of the state.
  bool filter(State& s, const Vec3<S>& d, const S ri[6]) const {
    if (config_.kalman.gate_chi2) {
      // Mahalanobis distance of the innovation under P- + R (R the covariance as fused:
      // turned when ri is).
      S p[6], r[6], sm[6], si[6];
      inverse(s.info, p);
      const Vec3<S> e = d - times(p, s.eta);
      p[0] += q2_;
      p[3] += q2_;
      p[5] += q2_;
      inverse(ri, r);
      for (int i = 0; i < 6; ++i) sm[i] = p[i] + r[i];
      inverse(sm, si);
      if (e.dot(times(si, e)) > *config_.kalman.gate_chi2) return false;
    }
    if (q2_ > S(0)) {
      predict(s.info, s.eta);
      if (s.xcount > S(0)) predict(s.xinfo, s.xeta);
      predict(s.kinfo, s.keta);
    }
    for (int i = 0; i < 6; ++i) s.info[i] += ri[i];
    s.eta += times(ri, d);
    return true;
  }
  // The process noise's prediction of an information pair: J <- (J^-1 + q^2 I)^-1, the mean
  // J^-1 eta kept.
  void predict(S info[6], Vec3<S>& eta) const {
    S p[6];
    inverse(info, p);
    const Vec3<S> mu = times(p, eta);
    p[0] += q2_;
    p[3] += q2_;
    p[5] += q2_;
    inverse(p, info);
    eta = times(info, mu);
  }
  // The filter's update with a contact apart from the patch, kept in J_x and eta_x as well.
  bool filter_apart(State& s, const Vec3<S>& d, const S ri[6]) const {
    if (!filter(s, d, ri)) return false;
    s.xcount += S(1);
    for (int i = 0; i < 6; ++i) s.xinfo[i] += ri[i];
    s.xeta += times(ri, d);
    return true;
  }
  // The inverse of a symmetric positive definite 3x3 matrix (upper triangle, row by row) by
  // its adjugate.
  static void inverse(const S m[6], S out[6]) noexcept {
    const S a = m[0], b = m[1], c = m[2], d = m[3], e = m[4], f = m[5];
    const S a00 = d * f - e * e, a01 = c * e - b * f, a02 = b * e - c * d;
    const S inv_det = S(1) / (a * a00 + b * a01 + c * a02);
    out[0] = a00 * inv_det;
    out[1] = a01 * inv_det;
    out[2] = a02 * inv_det;
    out[3] = (a * f - c * c) * inv_det;
    out[4] = (b * c - a * e) * inv_det;
    out[5] = (a * d - b * b) * inv_det;
  }
  static void inverse(const Mat3<S>& m, S out[6]) noexcept {
    const S u[6] = {m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)};
    inverse(u, out);
  }
  static Mat3<S> symmetric(const S m[6]) noexcept {
    Mat3<S> out;
    out << m[0], m[1], m[2], m[1], m[3], m[4], m[2], m[4], m[5];
    return out;
  }
  static Vec3<S> times(const S m[6], const Vec3<S>& x) noexcept {
    return {m[0] * x.x() + m[1] * x.y() + m[2] * x.z(), m[1] * x.x() + m[3] * x.y() + m[4] * x.z(),
            m[2] * x.x() + m[4] * x.y() + m[5] * x.z()};
  }
  // The weight of a contact's slope in the curvature fit, relative to its height's: 1 for a
  // normal as good as normal_sigma (or one that states no sigma_c), (normal_sigma / sigma_c)^2
  // for a worse one.
  S share(const Contact<S>& c) const noexcept {
    if (!(c.normal_sigma > config_.normal_sigma)) return S(1);
    const S r = config_.normal_sigma / c.normal_sigma;
    return r * r;
  }
  static void add_sums(State& s, S w, S k, S ux, S uy, S z, S sx, S sy) {
    s.weight += w;
    s.sz += w * z;
    s.su[0] += w * ux;
    s.su[1] += w * uy;
    s.suu[0] += w * ux * ux;
    s.suu[1] += w * ux * uy;
    s.suu[2] += w * uy * uy;
    const S v = w * k;
    s.vweight += v;
    s.vu[0] += v * ux;
    s.vu[1] += v * uy;
    s.ss[0] += v * sx;
    s.ss[1] += v * sy;
    s.vuu[0] += v * ux * ux;
    s.vuu[1] += v * ux * uy;
    s.vuu[2] += v * uy * uy;
    s.ssu[0] += v * sx * ux;
    s.ssu[1] += v * sx * uy;
    s.ssu[2] += v * sy * ux;
    s.ssu[3] += v * sy * uy;
    s.sss[0] += v * sx * sx;
    s.sss[1] += v * sx * sy;
    s.sss[2] += v * sy * sy;
  }

  Config config_{};
  S q2_ = S(0);                                      // process noise variance q^2 [m^2]
  S cos_max_ = S(0.36235775447667357);               // cos(1.2)
  S ridge_ = S(0.05) * S(0.05) / (S(100) * S(100));  // (normal_sigma / curvature_prior)^2
};

}  // namespace taxel::fusion
