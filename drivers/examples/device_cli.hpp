// SPDX-License-Identifier: MIT
// Shared by the driver tools: pad poses per frame as CSV text, static poses from the controller's
// matrix info, and the simulated hand that drives the emulated controller.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <taxel/drivers/convert.hpp>
#include <taxel/drivers/dsa_protocol.hpp>
#include <taxel/drivers/dsacon_emulator.hpp>
#include <taxel/io/file.hpp>
#include <taxel/sim.hpp>
#include <utility>
#include <vector>

namespace taxel_drivers_cli {

namespace dsa = taxel::drivers::dsa;
using Poses = std::vector<Eigen::Isometry3d>;

/// "A:B" as two numbers in `base`, each at most 0xFFFF (a USB VID:PID in hex, a bus:address
/// in decimal); nothing when the text has another form.
inline std::optional<std::pair<unsigned, unsigned>> parse_pair(const std::string& text, int base) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos) return std::nullopt;
  unsigned x = 0, y = 0;
  const char* mid = text.data() + colon;
  const char* end = text.data() + text.size();
  const auto r1 = std::from_chars(text.data(), mid, x, base);
  const auto r2 = std::from_chars(mid + 1, end, y, base);
  if (r1.ec != std::errc() || r2.ec != std::errc() || r1.ptr != mid || r2.ptr != end ||
      x > 0xFFFF || y > 0xFFFF) {
    return std::nullopt;
  }
  return std::pair<unsigned, unsigned>(x, y);
}

/// The text of poses in the drivers' form (time_ms,matrix,x,y,z,qw,qx,qy,qz), which
/// taxel::drivers::SessionPoses reads.
inline std::string poses_csv(const std::map<std::uint32_t, Poses>& poses) {
  std::ostringstream out;
  out << "time_ms,matrix,x,y,z,qw,qx,qy,qz\n";
  out.precision(9);
  for (const auto& [t, ps] : poses) {
    for (std::size_t i = 0; i < ps.size(); ++i) {
      const Eigen::Quaterniond q(ps[i].linear());
      const auto& x = ps[i].translation();
      out << t << ',' << i << ',' << x.x() << ',' << x.y() << ',' << x.z() << ',' << q.w() << ','
          << q.x() << ',' << q.y() << ',' << q.z() << '\n';
    }
  }
  return out.str();
}

/// Fixed pad poses from the matrix info (centre in mm, angles in rad, rotation
/// Rz * Ry * Rx): where the controller says each matrix sits in the hand frame.
inline Poses static_poses(const std::vector<dsa::MatrixInfo>& matrices) {
  return taxel::drivers::static_matrix_poses(matrices);
}

/// A simulated three-finger hand (two 14x6 pads per finger) grasping a shape: the frames the
/// emulated controller streams, and the poses forward kinematics would report.
struct SimulatedHand {
  std::vector<std::vector<std::uint16_t>> frames;  ///< tactels of each frame, pad after pad
  std::map<std::uint32_t, Poses> poses;            ///< believed pad poses by time stamp
  std::vector<dsa::MatrixInfo> matrices;           ///< six 14x6 matrices at 3.4 mm
};

template <class Shape>
SimulatedHand simulate_hand(const Shape& shape, int grasps, double period_ms, std::uint64_t seed) {
  taxel::sim::ExplorationConfig cfg;
  cfg.frame_rate = 1000.0 / period_ms;
  cfg.seed = seed;
  taxel::sim::GraspParams g;
  g.grasps = grasps;
  g.closing_speed = 0.01;
  g.hold_frames = 8;
  const auto ex = taxel::sim::explore_grasps(shape, cfg, g);
  SimulatedHand hand;
  for (int i = 0; i < g.fingers * g.pads_per_finger; ++i) {
    dsa::MatrixInfo m;
    m.texel_width = m.texel_height = float(cfg.sensor.geometry.pitch * 1e3);
    m.cells_x = static_cast<std::uint16_t>(cfg.sensor.geometry.cols);
    m.cells_y = static_cast<std::uint16_t>(cfg.sensor.geometry.rows);
    m.fullscale = float(cfg.sensor.levels - 1);
    m.uid = {0x54, 0x58, 0x4c, 0x00, std::uint8_t(i), 0x01};
    hand.matrices.push_back(m);
  }
  for (std::size_t f = 0; f < ex.frames.size(); ++f) {
    std::vector<std::uint16_t> texels;
    Poses poses;
    for (const auto& pad : ex.frames[f].pads) {
      texels.insert(texels.end(), pad.counts.data(), pad.counts.data() + pad.counts.size());
      poses.push_back(pad.believed_pose);
    }
    hand.frames.push_back(std::move(texels));
    // The emulator stamps frame i with round(i * period) ms.
    hand.poses[static_cast<std::uint32_t>(double(f) * period_ms + 0.5)] = std::move(poses);
  }
  return hand;
}

}  // namespace taxel_drivers_cli
