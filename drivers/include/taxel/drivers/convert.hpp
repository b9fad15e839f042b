// SPDX-License-Identifier: MIT
// From controller frames to what the rest of taxel eats: contacts with the pad's anisotropic
// covariance (for fusion::ContactCloud) and pressure images (for the image pipeline). The
// reading-to-contact model is sensor/contacts.hpp's, the one the simulator uses too, so simulated
// and real streams go through the same arithmetic.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/drivers/dsacon_device.hpp"
#include "taxel/image/types.hpp"
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

/// Matrix `i` of a frame as a pressure image (rows x cols, the raw readings as doubles).
inline image::ImageD frame_image(const TactileFrame& frame, std::size_t i) {
  if (i >= frame.matrices.size()) {
    throw std::out_of_range("frame_image: matrix " + std::to_string(i) + " of " +
                            std::to_string(frame.matrices.size()));
  }
  return frame.matrices[i].cast<double>();
}

}  // namespace taxel::drivers
