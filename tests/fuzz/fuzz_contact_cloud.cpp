// SPDX-License-Identifier: MIT
// Fuzzes ContactCloud::insert with arbitrary contacts (any bit patterns, NaN, Inf, huge,
// indefinite): it must never crash, reject exactly the invalid ones, and keep every fused
// point finite.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <taxel/fusion.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  taxel::fusion::ContactCloud<> cloud({.association_radius = 2e-3});
  constexpr std::size_t kDoubles = 3 + 6;  // position, upper triangle of the covariance
  while (size >= kDoubles * sizeof(double)) {
    double v[kDoubles];
    std::memcpy(v, data, sizeof v);
    data += sizeof v;
    size -= sizeof v;
    taxel::Contact<double> c;
    c.position = {v[0], v[1], v[2]};
    c.covariance << v[3], v[4], v[5], v[4], v[6], v[7], v[5], v[7], v[8];
    const bool valid = taxel::check_contact(c) == taxel::ContactDefect::ok;
    const std::size_t before = cloud.size();
    const auto r = cloud.insert(c);
    if (!valid && (r.status != taxel::fusion::InsertStatus::rejected || cloud.size() != before)) {
      std::abort();
    }
    if (r.status != taxel::fusion::InsertStatus::rejected && !cloud.mean(r.id).allFinite()) {
      std::abort();
    }
  }
  return 0;
}
