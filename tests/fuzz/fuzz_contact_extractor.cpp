// SPDX-License-Identifier: MIT
// Fuzzes sensor::ContactExtractor, differentially: the first bytes pick the pad size (1-16 x
// 1-16), the levels, the threshold, the mode and the options, and the model's lengths and
// noise over the whole range SensorModel::validate accepts (pitch 1 um - 1 m, full-scale
// depth 1e-12 - 1 m, noise 0 or 1e-9 - 1 m, tilt 0 - pi); the rest are frames of readings
// (two bytes a tactel, any value, saturated and above the levels included). Every frame goes
// through one extractor, which keeps its workspace from frame to frame, and through a new one:
// the contacts must be the same bits, and every contact valid (finite, symmetric positive
// definite covariance, unit normal); per tactel, there must be one contact per active tactel.
// Nothing may throw: the readings always fit the pad.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <numbers>
#include <taxel/core/contact.hpp>
#include <taxel/sensor/contacts.hpp>
#include <vector>

#include "byte_range.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::size_t kHeader = 11;
  if (size < kHeader) return 0;
  namespace tsn = taxel::sensor;
  tsn::SensorModel m;
  m.geometry.rows = 1 + data[0] % 16;
  m.geometry.cols = 1 + data[1] % 16;
  m.levels = 2 + (data[2] | (data[3] & 0x0f) << 8);  // 2 .. 4097
  m.threshold = 1 + data[4] % (m.levels - 1);
  using taxel::fuzz::log_range;
  m.geometry.pitch = log_range(data[6], 1e-6, 1.0);
  m.full_scale_depth = log_range(data[7], 1e-12, 1.0);
  m.sigma_normal = (data[5] & 0x10) ? 0.0 : log_range(data[8], 1e-9, 1.0);
  m.sigma_position = (data[5] & 0x20) ? 0.0 : log_range(data[9], 1e-9, 1.0);
  m.sigma_tilt = std::numbers::pi * (data[10] / 255.0);
  m.validate();  // (in range by construction: a throw here is a finding)
  const tsn::ContactOptions opt{
      .mode = (data[5] & 1) ? tsn::ContactMode::per_pad : tsn::ContactMode::per_tactel,
      .local_normals = (data[5] & 2) != 0,
      .correct_censoring = (data[5] & 4) != 0,
      .refine_censoring = (data[5] & 8) != 0};
  tsn::ContactExtractor reused(m, opt);
  const std::size_t tactels = static_cast<std::size_t>(m.geometry.rows) * m.geometry.cols;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(0.3, taxel::Vec3d(1, 2, 3).normalized()).matrix();
  std::vector<taxel::Contact<double>> a, b;
  for (std::size_t at = kHeader; at + 2 * tactels <= size; at += 2 * tactels) {
    tsn::PadMatrix counts(m.geometry.rows, m.geometry.cols);
    std::size_t active = 0;
    for (std::size_t i = 0; i < tactels; ++i) {
      // Values spread over the levels, with 0, the threshold and saturation common.
      const unsigned v = data[at + 2 * i] | data[at + 2 * i + 1] << 8;
      counts.data()[i] = static_cast<std::uint16_t>(v % (m.levels + 2));
      active += counts.data()[i] >= m.threshold && counts.data()[i] < m.levels - 1;
    }
    a.clear();
    b.clear();
    const std::size_t n = reused.extract(counts, pose, 0.0, a);
    // Per tactel, one contact per active tactel (threshold <= k < levels - 1).
    if (opt.mode == tsn::ContactMode::per_tactel && n != active) std::abort();
    tsn::ContactExtractor fresh(m, opt);
    if (fresh.extract(counts, pose, 0.0, b) != n || a.size() != n || b.size() != n) std::abort();
    for (std::size_t i = 0; i < n; ++i) {
      if (std::memcmp(a[i].position.data(), b[i].position.data(), 3 * sizeof(double)) != 0 ||
          std::memcmp(a[i].covariance.data(), b[i].covariance.data(), 9 * sizeof(double)) != 0 ||
          std::memcmp(a[i].normal->data(), b[i].normal->data(), 3 * sizeof(double)) != 0) {
        std::abort();
      }
      if (taxel::check_contact(a[i]) != taxel::ContactDefect::ok) std::abort();
    }
  }
  return 0;
}
