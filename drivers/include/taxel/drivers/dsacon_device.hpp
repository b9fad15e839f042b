// SPDX-License-Identifier: MIT
// A DSACON32m tactile controller over any Transport: handshake, streaming, time-stamped frames
// with dropped-frame accounting, and a clean stop on close.
#pragma once

#include <Eigen/Core>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "taxel/drivers/dsa_protocol.hpp"
#include "taxel/drivers/transport.hpp"

namespace taxel::drivers {

/// Tactel values of one matrix: cells_y rows x cells_x columns, row-major.
using TexelMatrix = Eigen::Array<std::uint16_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// One frame from the controller.
struct TactileFrame {
  /// Position in the stream: frames delivered plus frames detected as dropped before this one.
  std::uint64_t sequence = 0;
  std::uint32_t device_time_ms = 0;                 ///< the controller's clock [ms]
  std::chrono::steady_clock::time_point host_time;  ///< when the host finished receiving it
  std::uint64_t dropped_before = 0;                 ///< frames missing just before this one
  std::vector<TexelMatrix> matrices;                ///< one per matrix, in controller order
};

/// Timeouts and options of a DsaconDevice.
struct DsaconConfig {
  Timeout reply_timeout{1000};   ///< per command reply
  Timeout frame_timeout{1000};   ///< read_frame gives up after this
  int open_attempts = 4;         ///< tries of the initial stop (a booting controller is mute)
  bool rle = true;               ///< ask for run-length encoded frames
  std::uint16_t frame_rate = 0;  ///< acquisition rate field; 0 streams at the highest rate
  std::size_t max_payload = dsa::kDefaultMaxPayload;
};

/// What the device saw; nothing is dropped silently.
struct DsaconStats {
  std::uint64_t frames = 0;              ///< frames delivered
  std::uint64_t dropped_frames = 0;      ///< gaps in the controller clock, in frame periods
  std::uint64_t bad_frames = 0;          ///< frame packets that failed to decode
  std::uint64_t discarded_frames = 0;    ///< frames arriving while not streaming (before a stop)
  std::uint64_t unexpected_packets = 0;  ///< replies nobody asked for
  dsa::ParserStats link;                 ///< framing: CRC errors, oversized, skipped bytes
};

/// A DSACON32m controller behind transport T. open() performs the handshake (stop any stream a
/// previous client left running, query controller, sensor and matrix configuration); start() and
/// stop() control streaming; read_frame() returns frames. On a transport error the partial
/// packet is discarded (never half a frame), the error propagates, and open() may be called
/// again to reconnect. The destructor stops the stream.
template <Transport T>
class DsaconDevice {
 public:
  explicit DsaconDevice(T transport, DsaconConfig cfg = {})
      : transport_(std::move(transport)), cfg_(cfg), parser_(cfg.max_payload) {}
  DsaconDevice(const DsaconDevice&) = delete;
  DsaconDevice& operator=(const DsaconDevice&) = delete;
  ~DsaconDevice() {
    try {
      close();
    } catch (...) {  // closing a broken link: nothing more to do
    }
  }

  /// Connects and reads the configuration. Throws TransportError or dsa::ProtocolError.
  void open() {
    streaming_ = false;
    parser_.reset();
    frames_.clear();
    last_stamp_.reset();
    if (!transport_.is_open()) transport_.open();
    // A controller may still stream for a previous client, or still boot (mute for about 8 s):
    // stop it, retrying.
    for (int attempt = 1;; ++attempt) {
      try {
        command(dsa::encode_set_acquisition(0, false, cfg_.rle), dsa::PacketId::acquisition);
        break;
      } catch (const TransportError& e) {
        if (e.kind() != TransportErrorKind::timeout || attempt >= cfg_.open_attempts) throw;
      }
    }
    controller_ = dsa::decode_controller_info(
        command(dsa::encode_query_controller_info(), dsa::PacketId::controller_info));
    sensor_ = dsa::decode_sensor_info(
        command(dsa::encode_query_sensor_info(), dsa::PacketId::sensor_info));
    if (sensor_.matrices == 0 || sensor_.matrices > 64) {
      throw dsa::ProtocolError("sensor info: " + std::to_string(sensor_.matrices) +
                               " matrices, expected 1-64");
    }
    matrices_.clear();
    cells_ = 0;
    for (std::uint16_t i = 0; i < sensor_.matrices; ++i) {
      const dsa::MatrixInfo m = dsa::decode_matrix_info(command(
          dsa::encode_query_matrix_info(static_cast<std::uint8_t>(i)), dsa::PacketId::matrix_info));
      if (m.error_code != 0) {
        throw dsa::ProtocolError("matrix " + std::to_string(i) + ": controller error code " +
                                 std::to_string(m.error_code));
      }
      if (m.cells_x == 0 || m.cells_y == 0 || m.cells() > 4096) {
        throw dsa::ProtocolError("matrix " + std::to_string(i) + ": " + std::to_string(m.cells_x) +
                                 " x " + std::to_string(m.cells_y) +
                                 " cells, expected 1-4096 in all");
      }
      cells_ += m.cells();
      matrices_.push_back(m);
    }
    if (5 + 2 * cells_ > cfg_.max_payload) {
      throw dsa::ProtocolError("the matrices hold " + std::to_string(cells_) +
                               " tactels, more than a frame of max_payload bytes can carry");
    }
    opened_ = true;
  }

  /// Starts streaming (acquisition on, RLE as configured).
  void start() {
    require_open("start");
    streaming_ = true;  // frames may arrive before the acknowledgement: keep them
    last_stamp_.reset();
    command(dsa::encode_set_acquisition(cfg_.frame_rate, true, cfg_.rle),
            dsa::PacketId::acquisition);
  }

  /// Stops streaming; frames still in flight are counted as discarded.
  void stop() {
    require_open("stop");
    streaming_ = false;
    frames_.clear();
    command(dsa::encode_set_acquisition(0, false, cfg_.rle), dsa::PacketId::acquisition);
  }

  /// Stops the stream (best effort) and closes the transport.
  void close() {
    if (opened_ && transport_.is_open()) {
      try {
        if (streaming_) stop();
      } catch (const TransportError&) {
      } catch (const dsa::ProtocolError&) {
      }
    }
    opened_ = false;
    streaming_ = false;
    if (transport_.is_open()) transport_.close();
  }

  /// The next frame, or nothing when none arrives within frame_timeout. Throws TransportError
  /// (the link failed: reopen) and dsa::ProtocolError only for a protocol-level refusal.
  std::optional<TactileFrame> read_frame() {
    require_open("read_frame");
    const auto deadline = std::chrono::steady_clock::now() + cfg_.frame_timeout;
    for (;;) {
      drain(dsa::PacketId::frame);
      if (!frames_.empty()) {
        TactileFrame f = std::move(frames_.front());
        frames_.pop_front();
        return f;
      }
      const auto now = std::chrono::steady_clock::now();
      if (now >= deadline) return std::nullopt;
      pump(std::chrono::duration_cast<Timeout>(deadline - now));
    }
  }

  bool is_open() const noexcept { return opened_; }
  bool streaming() const noexcept { return streaming_; }
  const dsa::ControllerInfo& controller_info() const noexcept { return controller_; }
  const dsa::SensorInfo& sensor_info() const noexcept { return sensor_; }
  const std::vector<dsa::MatrixInfo>& matrices() const noexcept { return matrices_; }
  std::size_t cells() const noexcept { return cells_; }
  /// Bytes received but not yet a whole packet: after the last frame of a finished stream, a
  /// non-zero count means that frame was cut off.
  std::size_t unparsed_bytes() const noexcept { return parser_.buffered(); }
  DsaconStats stats() const {
    DsaconStats s = stats_;
    s.link = parser_.stats();
    return s;
  }
  T& transport() noexcept { return transport_; }

 private:
  void require_open(const char* what) const {
    if (!opened_) {
      throw TransportError(TransportErrorKind::not_open,
                           std::string("DsaconDevice::") + what + ": the device is not open");
    }
  }

  // Reads once from the transport into the parser; a link error drops the partial packet.
  void pump(Timeout timeout) {
    std::uint8_t buf[4096];
    std::size_t n = 0;
    try {
      n = transport_.read(buf, timeout);
    } catch (const TransportError&) {
      parser_.reset();
      streaming_ = false;
      opened_ = false;
      throw;
    }
    parser_.feed(std::span<const std::uint8_t>(buf, n));
  }

  // Sorts parsed packets: frames into the frame queue, `want` into `reply`.
  void drain(dsa::PacketId want, std::optional<dsa::Packet>* reply = nullptr) {
    while (auto p = parser_.next()) {
      if (p->id == std::uint8_t(dsa::PacketId::frame)) {
        if (!streaming_ || cells_ == 0) {
          ++stats_.discarded_frames;
          continue;
        }
        accept_frame(p->payload);
      } else if (reply != nullptr && p->id == std::uint8_t(want) && !reply->has_value()) {
        *reply = std::move(*p);
      } else {
        ++stats_.unexpected_packets;
      }
    }
  }

  void accept_frame(std::span<const std::uint8_t> payload) {
    dsa::RawFrame raw;
    try {
      raw = dsa::decode_frame(payload, cells_);
    } catch (const dsa::ProtocolError&) {
      ++stats_.bad_frames;
      return;
    }
    TactileFrame f;
    f.device_time_ms = raw.timestamp_ms;
    f.host_time = std::chrono::steady_clock::now();
    if (last_stamp_) {
      const std::uint32_t delta = raw.timestamp_ms - *last_stamp_;  // wraps like the clock
      if (delta > 0 && (period_ms_ == 0 || delta < period_ms_)) period_ms_ = delta;
      if (period_ms_ > 0 && delta * 2 > 3 * period_ms_) {
        f.dropped_before =
            static_cast<std::uint64_t>(std::llround(double(delta) / double(period_ms_))) - 1;
      }
    }
    last_stamp_ = raw.timestamp_ms;
    stats_.dropped_frames += f.dropped_before;
    f.sequence = sequence_ + f.dropped_before;
    sequence_ = f.sequence + 1;
    std::size_t at = 0;
    for (const auto& m : matrices_) {
      TexelMatrix t(m.cells_y, m.cells_x);
      std::copy_n(raw.texels.begin() + long(at), m.cells(), t.data());
      at += m.cells();
      f.matrices.push_back(std::move(t));
    }
    ++stats_.frames;
    frames_.push_back(std::move(f));
  }

  // Sends a command and returns the payload of its reply; checks acknowledgements.
  std::vector<std::uint8_t> command(const std::vector<std::uint8_t>& bytes, dsa::PacketId want) {
    transport_.write(bytes, cfg_.reply_timeout);
    const auto deadline = std::chrono::steady_clock::now() + cfg_.reply_timeout;
    std::optional<dsa::Packet> reply;
    for (;;) {
      drain(want, &reply);
      if (reply) break;
      const auto now = std::chrono::steady_clock::now();
      if (now >= deadline) {
        throw TransportError(TransportErrorKind::timeout,
                             "DSACON32m: no reply to command 0x" + hex(std::uint8_t(want)) +
                                 " within " + std::to_string(cfg_.reply_timeout.count()) + " ms");
      }
      pump(std::chrono::duration_cast<Timeout>(deadline - now));
    }
    if (want == dsa::PacketId::acquisition) {
      const std::uint16_t code = dsa::decode_error_code(reply->payload);
      if (code != 0) {
        throw dsa::ProtocolError("DSACON32m refused the acquisition command: error code " +
                                 std::to_string(code));
      }
    }
    return std::move(reply->payload);
  }

  static std::string hex(std::uint8_t v) {
    static constexpr char k[] = "0123456789abcdef";
    return {k[v >> 4], k[v & 15]};
  }

  T transport_;
  DsaconConfig cfg_;
  dsa::Parser parser_;
  dsa::ControllerInfo controller_;
  dsa::SensorInfo sensor_;
  std::vector<dsa::MatrixInfo> matrices_;
  std::size_t cells_ = 0;
  bool opened_ = false;
  bool streaming_ = false;
  std::deque<TactileFrame> frames_;
  std::optional<std::uint32_t> last_stamp_;
  std::uint32_t period_ms_ = 0;
  std::uint64_t sequence_ = 0;
  DsaconStats stats_;
};

}  // namespace taxel::drivers
