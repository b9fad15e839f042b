// SPDX-License-Identifier: MIT
// From controller frames to what the rest of taxel eats: contacts with the pad's anisotropic
// covariance (for fusion::ContactCloud) and pressure images (for the image pipeline). The
// reading-to-contact model is sensor/contacts.hpp's, the one the simulator uses too, so simulated
// and real streams go through the same arithmetic.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/error.hpp"
#include "taxel/drivers/dsacon_device.hpp"
#include "taxel/image/types.hpp"
#include "taxel/io/pad_poses_csv.hpp"
#include "taxel/sensor/contacts.hpp"
#include "taxel/sim/sensor.hpp"

namespace taxel::drivers {

/// How a matrix's readings map to depth and how noisy its pose is; the geometry comes from the
/// controller's matrix info.
struct PadCalibration {
  double full_scale_depth = 3e-3;  ///< indentation at the largest reading [m]
  int threshold = 8;               ///< readings below this are no contact
  double sigma_normal = 0.3e-3;    ///< depth noise [m]
  double sigma_position = 0.2e-3;  ///< kinematic translation noise of the pad pose [m]
  double sigma_tilt = 0.02;        ///< kinematic rotation noise of the pad pose [rad]
};

/// The sensor model of a matrix: its rows, columns and pitch (texel size, mm -> m) and levels
/// (fullscale + 1) from the controller, the rest from `cal`. Throws std::invalid_argument for a
/// matrix whose texels are not square (within 1 %) or a bad calibration.
inline sim::SensorModel sensor_model(const dsa::MatrixInfo& m, const PadCalibration& cal = {}) {
  if (!(m.texel_width > 0) || std::abs(m.texel_width - m.texel_height) > 0.01 * m.texel_width) {
    throw std::invalid_argument("sensor_model: texels of " + std::to_string(m.texel_width) + " x " +
                                std::to_string(m.texel_height) + " mm; square texels are expected");
  }
  sim::SensorModel s;
  s.geometry.rows = m.cells_y;
  s.geometry.cols = m.cells_x;
  s.geometry.pitch = 1e-3 * double(m.texel_width);
  s.levels = m.fullscale >= 1.0f && m.fullscale < 65535.0f ? int(m.fullscale) + 1 : 4096;
  s.full_scale_depth = cal.full_scale_depth;
  s.threshold = cal.threshold;
  s.sigma_normal = cal.sigma_normal;
  s.sigma_position = cal.sigma_position;
  s.sigma_tilt = cal.sigma_tilt;
  s.validate();
  return s;
}

/// The matrices' poses on the hand as the controller describes them (centre [mm] and the
/// x-y-z Euler angles [rad] of its matrix info), as pad -> hand isometries [m]: the poses of a
/// hand whose joints do not move, or a fallback when no kinematics are at hand.
inline std::vector<Eigen::Isometry3d> static_matrix_poses(
    std::span<const dsa::MatrixInfo> matrices) {
  std::vector<Eigen::Isometry3d> out;
  out.reserve(matrices.size());
  for (const auto& m : matrices) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = (Eigen::AngleAxisd(m.theta[2], Vec3d::UnitZ()) *
                  Eigen::AngleAxisd(m.theta[1], Vec3d::UnitY()) *
                  Eigen::AngleAxisd(m.theta[0], Vec3d::UnitX()))
                     .toRotationMatrix();
    T.translation() = 1e-3 * Vec3d(m.center[0], m.center[1], m.center[2]);
    out.push_back(T);
  }
  return out;
}

/// Appends the contacts of `frame` to `out`: matrix i at `pad_poses[i]` (pad -> world, from the
/// hand's kinematics; the pad frame of sim/sensor.hpp). Readings below the calibration's
/// threshold are ignored. Time: the controller clock in seconds. Returns the count appended.
/// Throws std::invalid_argument when the poses do not match the matrices.
inline std::size_t frame_contacts(const TactileFrame& frame,
                                  std::span<const dsa::MatrixInfo> matrices,
                                  std::span<const Eigen::Isometry3d> pad_poses,
                                  std::vector<Contact<double>>& out,
                                  sim::ContactMode mode = sim::ContactMode::per_tactel,
                                  const PadCalibration& cal = {},
                                  const sensor::ContactOptions& options = {}) {
  if (frame.matrices.size() != matrices.size() || pad_poses.size() != matrices.size()) {
    throw std::invalid_argument("frame_contacts: " + std::to_string(frame.matrices.size()) +
                                " matrices in the frame, " + std::to_string(matrices.size()) +
                                " described, " + std::to_string(pad_poses.size()) + " poses");
  }
  std::size_t n = 0;
  for (std::size_t i = 0; i < matrices.size(); ++i) {
    sensor::ContactOptions o = options;
    o.mode = mode;
    sensor::ContactExtractor extractor(sensor_model(matrices[i], cal), o);
    n += extractor.extract(frame.matrices[i], pad_poses[i], 1e-3 * double(frame.device_time_ms),
                           out);
  }
  return n;
}

/// Pad poses of a recorded session, by the controller's time stamp: the world pose of each
/// matrix at each frame time, read from a pad poses CSV in the drivers' form (columns time_ms and
/// matrix, as taxel-record --poses writes it; io/pad_poses_csv.hpp).
class SessionPoses {
 public:
  SessionPoses() = default;

  /// Reads `text` for a session of `matrices` matrices. Throws taxel::IoError naming `source`:
  /// for the frame,pad form (its frames count a stack of readings, not the controller's clock),
  /// a matrix index beyond the session's, and what io::parse_pad_poses_csv refuses.
  SessionPoses(std::string_view text, const std::string& source, std::size_t matrices) {
    io::LineReader lines(text);
    std::string_view header;
    while (lines.next(header) && io::blank_or_comment(header)) {
    }
    bool time_ms = false, frame = false;
    for (std::size_t at = 0; at <= header.size();) {
      const std::size_t comma = std::min(header.find(',', at), header.size());
      std::string_view cell = header.substr(at, comma - at);
      while (!cell.empty() && cell.front() == ' ') cell.remove_prefix(1);
      while (!cell.empty() && cell.back() == ' ') cell.remove_suffix(1);
      time_ms = time_ms || cell == "time_ms";
      frame = frame || cell == "frame";
      at = comma + 1;
    }
    if (frame || !time_ms) {
      throw IoError(source,
                    "a session's poses are keyed by the controller's clock: the header needs "
                    "time_ms and matrix (as taxel-record --poses writes them), not frame and pad",
                    lines.line_number());
    }
    for (const io::PadPose& p : io::parse_pad_poses_csv(text, source)) {
      if (p.pad >= matrices) {
        throw IoError(source, "matrix " + std::to_string(p.pad) + " at time_ms " +
                                  std::to_string(std::llround(p.time * 1e3)) +
                                  ": the session has " + std::to_string(matrices) +
                                  " matrices (0 to " + std::to_string(matrices - 1) + ")");
      }
      auto& row = table_[static_cast<std::uint32_t>(std::llround(p.time * 1e3))];
      row.resize(matrices);
      row[p.pad] = p.pose;
    }
  }

  /// True when no pose was read.
  [[nodiscard]] bool empty() const noexcept { return table_.empty(); }

  /// The poses of `frame`'s matrices into `out`: the table's at the frame's time stamp, or all
  /// of `fallback` when the table is empty. A matrix without a pose that reads no contact
  /// (every reading below `threshold`) gets `fallback`'s pose, which places nothing. Returns
  /// true when the table has a row at the frame's time. Throws taxel::IoError naming `source`
  /// when a matrix that reads contact has no pose, as readings without a pose are refused.
  bool frame_poses(const TactileFrame& frame, std::span<const Eigen::Isometry3d> fallback,
                   int threshold, const std::string& source,
                   std::vector<Eigen::Isometry3d>& out) const {
    out.assign(fallback.begin(), fallback.end());
    if (table_.empty()) return false;
    const auto it = table_.find(frame.device_time_ms);
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (it != table_.end() && i < it->second.size() && it->second[i]) {
        out[i] = *it->second[i];
      } else if (i < frame.matrices.size() &&
                 (frame.matrices[i].template cast<int>() >= threshold).any()) {
        throw IoError(source, "no pose for matrix " + std::to_string(i) + " at time_ms " +
                                  std::to_string(frame.device_time_ms) +
                                  ", where the session's frame reads contact on it");
      }
    }
    return it != table_.end();
  }

 private:
  std::map<std::uint32_t, std::vector<std::optional<Eigen::Isometry3d>>> table_;
};

/// Matrix `i` of a frame as a pressure image (rows x cols, the raw readings as doubles).
inline image::ImageD frame_image(const TactileFrame& frame, std::size_t i) {
  if (i >= frame.matrices.size()) {
    throw std::out_of_range("frame_image: matrix " + std::to_string(i) + " of " +
                            std::to_string(frame.matrices.size()));
  }
  return frame.matrices[i].cast<double>();
}

}  // namespace taxel::drivers
