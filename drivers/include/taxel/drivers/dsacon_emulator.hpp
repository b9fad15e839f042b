// SPDX-License-Identifier: MIT
// A DSACON32m controller in software: answers the queries and acquisition commands as the
// real controller does (dsa_protocol.hpp) and streams frames from a caller's source. For tests
// without hardware, for trying the tools, and for producing recorded sessions from simulated
// explorations.
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "taxel/drivers/dsa_protocol.hpp"
#include "taxel/drivers/transport.hpp"

namespace taxel::drivers {

/// The matrices of a SCHUNK SDH-2 hand: three fingers, each with a proximal 6x14 and a distal
/// 6x13 matrix at 3.4 mm, 486 tactels (SCHUNK's SDH-2 documentation). Centres and angles are
/// nominal.
inline std::vector<dsa::MatrixInfo> sdh2_matrices() {
  std::vector<dsa::MatrixInfo> m;
  for (int finger = 0; finger < 3; ++finger) {
    for (int part = 0; part < 2; ++part) {
      dsa::MatrixInfo info;
      info.texel_width = info.texel_height = 3.4f;
      info.cells_x = 6;
      info.cells_y = part == 0 ? 14 : 13;
      info.uid = {0x44, 0x53, 0x41, std::uint8_t(finger), std::uint8_t(part), 0x01};
      info.hw_revision = 1;
      const float angle = 2.0943951f * float(finger);  // fingers 120 degrees apart
      info.center = {0.0f, 0.0f, part == 0 ? 50.0f : 135.0f};
      info.theta = {0.0f, 0.0f, angle};
      info.fullscale = 4095.0f;
      m.push_back(info);
    }
  }
  return m;
}

/// Configuration of the emulated controller.
struct EmulatorConfig {
  dsa::ControllerInfo controller{0, 0x00C0FFEE, 1, 288, 0, 0, 1, 0, 1000000, 42};
  std::uint32_t sensor_serial = 0x5E5501;
  std::vector<dsa::MatrixInfo> matrices = sdh2_matrices();
  double period_ms = 1000.0 / 30.0;  ///< frame period while streaming (about 30 fps)
  bool streaming_at_start = false;   ///< as a controller a previous client left streaming
};

/// The emulated controller. Not thread-safe; serve() runs it on one thread.
class DsaconEmulator {
 public:
  /// Tactel values of frame `index`, matrix after matrix, row-major; must hold cells() values.
  using FrameSource = std::function<std::vector<std::uint16_t>(std::uint64_t index)>;

  explicit DsaconEmulator(EmulatorConfig cfg = {}, FrameSource source = {})
      : cfg_(std::move(cfg)), source_(std::move(source)), streaming_(cfg_.streaming_at_start) {
    for (const auto& m : cfg_.matrices) cells_ += m.cells();
  }

  /// Takes bytes from the host; returns the controller's replies to complete commands.
  std::vector<std::uint8_t> receive(std::span<const std::uint8_t> bytes) {
    parser_.feed(bytes);
    std::vector<std::uint8_t> out;
    while (auto p = parser_.next()) {
      const auto append = [&](const std::vector<std::uint8_t>& pkt) {
        out.insert(out.end(), pkt.begin(), pkt.end());
      };
      switch (static_cast<dsa::PacketId>(p->id)) {
        case dsa::PacketId::controller_info:
          append(dsa::encode_packet(p->id, dsa::encode_controller_info(cfg_.controller)));
          break;
        case dsa::PacketId::sensor_info: {
          dsa::SensorInfo s;
          s.matrices = static_cast<std::uint16_t>(cfg_.matrices.size());
          s.generated_by = 1;
          s.hw_revision = 1;
          s.serial_no = cfg_.sensor_serial;
          append(dsa::encode_packet(p->id, dsa::encode_sensor_info(s)));
          break;
        }
        case dsa::PacketId::matrix_info: {
          dsa::MatrixInfo m;
          if (p->payload.size() == 1 && p->payload[0] < cfg_.matrices.size()) {
            m = cfg_.matrices[p->payload[0]];
          } else {
            m.error_code = 1;  // not success: no such matrix
          }
          append(dsa::encode_packet(p->id, dsa::encode_matrix_info(m)));
          break;
        }
        case dsa::PacketId::acquisition: {
          std::uint16_t error = 0;
          if (p->payload.size() == 3) {
            streaming_ = (p->payload[0] & 0x80) != 0;
            rle_ = (p->payload[0] & 0x01) != 0;
          } else {
            error = 1;
          }
          const std::uint8_t ack[2] = {std::uint8_t(error), std::uint8_t(error >> 8)};
          append(dsa::encode_packet(p->id, ack));
          break;
        }
        default:
          ++unknown_;
          break;
      }
    }
    return out;
  }

  /// The bytes of the next frame; advances the frame index and the controller clock.
  std::vector<std::uint8_t> next_frame() {
    std::vector<std::uint16_t> texels =
        source_ ? source_(index_) : std::vector<std::uint16_t>(cells_, 0);
    if (texels.size() != cells_) {
      throw std::invalid_argument("DsaconEmulator: the frame source gave " +
                                  std::to_string(texels.size()) + " tactels, expected " +
                                  std::to_string(cells_));
    }
    const auto stamp = static_cast<std::uint32_t>(double(index_) * cfg_.period_ms + 0.5);
    ++index_;
    return dsa::encode_packet(std::uint8_t(dsa::PacketId::frame),
                              dsa::encode_frame(stamp, texels, rle_));
  }

  bool streaming() const noexcept { return streaming_; }
  std::size_t cells() const noexcept { return cells_; }
  std::uint64_t frames_sent() const noexcept { return index_; }
  std::size_t unknown_commands() const noexcept { return unknown_; }
  const EmulatorConfig& config() const noexcept { return cfg_; }

  /// Runs the controller on `end` until `stop`: answers commands and, while streaming, sends a
  /// frame every period (in real time when `realtime`, else as fast as the link takes them).
  /// Returns when `stop` is set or the link reports an error.
  template <Transport T>
  void serve(T& end, const std::atomic<bool>& stop, bool realtime = true) {
    std::uint8_t buf[512];
    auto due = std::chrono::steady_clock::now();
    const auto period = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
        std::chrono::duration<double, std::milli>(cfg_.period_ms));
    try {
      while (!stop.load()) {
        const std::size_t n = end.read(buf, Timeout(streaming_ ? 0 : 5));
        if (n > 0) {
          const auto reply = receive(std::span<const std::uint8_t>(buf, n));
          if (!reply.empty()) end.write(reply, Timeout(1000));
        }
        if (streaming_ && (!realtime || std::chrono::steady_clock::now() >= due)) {
          end.write(next_frame(), Timeout(1000));
          due += period;
          if (!realtime) std::this_thread::yield();
        } else if (streaming_) {
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        } else {
          due = std::chrono::steady_clock::now();
        }
      }
    } catch (const TransportError&) {
      // The link went away: a real controller would keep running; the emulator returns.
    }
  }

 private:
  EmulatorConfig cfg_;
  FrameSource source_;
  dsa::Parser parser_;
  std::size_t cells_ = 0;
  std::uint64_t index_ = 0;
  bool streaming_ = false;
  bool rle_ = false;
  std::size_t unknown_ = 0;
};

}  // namespace taxel::drivers
