// SPDX-License-Identifier: MIT
// Fuzzes ContactCloud::insert with arbitrary contacts (any bit patterns, NaN, Inf, huge,
// indefinite; with a normal or without) and association gates (association_sigmas from the
// first byte, so huge covariances widen the gate without bound), with Surfel's filter plain,
// with process noise, with a Mahalanobis gate or both (also from the first byte), and the
// association radius and Surfel's normal noise, curvature prior and largest normal angle from
// the next four bytes, over the whole ranges the configurations accept: it must never crash,
// reject exactly the invalid ones, and keep every fused point (mean, covariance and normal)
// finite.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <taxel/fusion.hpp>

#include "byte_range.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kHeader = 5;
  if (size < kHeader) return 0;
  const double sigmas = double(data[0] % 16);  // 0 (fixed gate) .. 15
  taxel::fusion::Kalman<double>::Config filter;
  if (data[0] & 16) filter.process_noise = 1e-4;
  if (data[0] & 32) filter.gate_chi2 = taxel::fusion::kChi2Dof3P99;
  // The radius up to the metre the cloud accepts, the policy's scales over the ranges Surfel
  // accepts, the angle over (0, pi/2).
  using taxel::fuzz::log_range;
  const double radius = log_range(data[1], 1e-7, 1.0);
  const taxel::fusion::Surfel<double>::Config policy{
      .kalman = filter,
      .max_normal_angle = 1.5707963267948966 * (0.5 + data[2]) / 256.0,
      .normal_sigma = log_range(data[3], 1e-6, 3.141592653589793),
      .curvature_prior = log_range(data[4], 1e-6, 1e9)};
  data += kHeader;
  size -= kHeader;
  taxel::fusion::ContactCloud<> cloud(
      {.association_radius = radius, .association_sigmas = sigmas, .fusion = policy});
  const taxel::fusion::Surfel<double> surfel(policy);  // the cloud's policy
  // Position, upper triangle of the covariance, normal (used when its first byte is odd).
  constexpr std::size_t kDoubles = 3 + 6 + 3;
  while (size >= kDoubles * sizeof(double)) {
    double v[kDoubles];
    std::memcpy(v, data, sizeof v);
    data += sizeof v;
    size -= sizeof v;
    taxel::Contact<double> c;
    c.position = {v[0], v[1], v[2]};
    c.covariance << v[3], v[4], v[5], v[4], v[6], v[7], v[5], v[7], v[8];
    std::uint8_t flag = 0;
    std::memcpy(&flag, &v[9], 1);
    if (flag & 1) {
      const taxel::Vec3d n(v[9], v[10], v[11]);
      // Mostly unit normals (a finite, non-zero vector normalised), sometimes the raw bits.
      c.normal = (flag & 2) && n.allFinite() && n.norm() > 0 ? taxel::Vec3d(n.normalized()) : n;
      // Sometimes a stated normal uncertainty: any bits, so also huge, negative or NaN.
      if (flag & 4) c.normal_sigma = v[10];
    }
    const bool valid = taxel::check_contact(c) == taxel::ContactDefect::ok;
    const std::size_t before = cloud.size();
    const auto r = cloud.insert(c);
    if (!valid && (r.status != taxel::fusion::InsertStatus::rejected || cloud.size() != before)) {
      std::abort();
    }
    // A valid contact is refused only for overflow or a position beyond the index's exact
    // range, and then leaves the cloud as it was.
    if (valid && r.status == taxel::fusion::InsertStatus::rejected &&
        ((r.defect != taxel::ContactDefect::overflow &&
          r.defect != taxel::ContactDefect::out_of_range) ||
         cloud.size() != before)) {
      std::abort();
    }
    if (r.status != taxel::fusion::InsertStatus::rejected &&
        (!cloud.mean(r.id).allFinite() || !cloud.covariance(r.id).allFinite() ||
         !surfel.normal(cloud.state(r.id)).allFinite())) {
      std::abort();
    }
  }
  return 0;
}
