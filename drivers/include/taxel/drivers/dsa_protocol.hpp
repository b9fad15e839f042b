// SPDX-License-Identifier: MIT
// The Weiss DSACON32m tactile controller protocol (as SCHUNK's SDHLibrary speaks it, files
// dsa.h, dsa.cpp and crc.cpp): packet framing, the CRC, command
// encoders, an incremental parser that resynchronises on garbage, and typed replies. Pure
// byte handling: no I/O, no device code.
//
// A packet on the wire:
//   AA AA AA | id (u8) | size (u16 LE) | payload (size bytes) | CRC-16 (u16 LE, only if size > 0)
// The CRC covers id, both size bytes and the payload.
#pragma once

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <deque>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace taxel::drivers::dsa {

static_assert(std::endian::native == std::endian::little,
              "the DSACON32m codec assumes a little-endian host");

/// Packet ids used by taxel (dsa.cpp's eDSAPacketID).
enum class PacketId : std::uint8_t {
  frame = 0x00,            ///< a full tactile frame (pushed while streaming)
  controller_info = 0x01,  ///< query controller configuration
  sensor_info = 0x02,      ///< query sensor configuration
  acquisition = 0x03,      ///< configure data acquisition (frame rate, RLE, start/stop)
  matrix_info = 0x0B,      ///< query one matrix's configuration
};

/// A protocol violation: malformed or unexpected bytes. The message says what and where.
struct ProtocolError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

namespace detail {
// The DSACON32m table holds the MSB-first CRC-CCITT remainders (polynomial 0x1021) of each byte,
// but the controller steps it LSB-first: crc = (crc >> 8) ^ table[(crc ^ byte) & 0xFF]. This
// mixture is what the device computes; it is not one of the catalogued CRC-16 variants.
constexpr std::array<std::uint16_t, 256> make_crc_table() {
  std::array<std::uint16_t, 256> t{};
  for (unsigned i = 0; i < 256; ++i) {
    unsigned r = i << 8;
    for (int b = 0; b < 8; ++b) r = (r & 0x8000u) ? ((r << 1) ^ 0x1021u) : (r << 1);
    t[i] = static_cast<std::uint16_t>(r & 0xFFFFu);
  }
  return t;
}
}  // namespace detail

/// The CRC table (exposed for tests: entries 1, 8 and 16 are 0x1021, 0x8108 and 0x1231).
inline constexpr std::array<std::uint16_t, 256> kCrcTable = detail::make_crc_table();

/// Continues a DSACON32m CRC-16 over `bytes` (start: 0xFFFF).
constexpr std::uint16_t crc16(std::span<const std::uint8_t> bytes,
                              std::uint16_t crc = 0xFFFF) noexcept {
  for (const std::uint8_t b : bytes)
    crc = static_cast<std::uint16_t>((crc >> 8) ^ kCrcTable[(crc ^ b) & 0xFFu]);
  return crc;
}

/// Largest payload the parser accepts by default: a raw frame of 4096 tactels plus header.
inline constexpr std::size_t kDefaultMaxPayload = 5 + 2 * 4096;

/// One packet: id and payload.
struct Packet {
  std::uint8_t id = 0;
  std::vector<std::uint8_t> payload;
};

/// The bytes of a packet with the given id and payload (CRC appended when the payload is not
/// empty). Throws std::length_error for a payload over 65535 bytes.
inline std::vector<std::uint8_t> encode_packet(std::uint8_t id,
                                               std::span<const std::uint8_t> payload) {
  if (payload.size() > 0xFFFF)
    throw std::length_error("dsa::encode_packet: payload over 65535 bytes");
  const std::size_t n = payload.size();
  std::vector<std::uint8_t> out(6 + n + (n > 0 ? 2 : 0));
  out[0] = out[1] = out[2] = 0xAA;
  out[3] = id;
  out[4] = static_cast<std::uint8_t>(n);
  out[5] = static_cast<std::uint8_t>(n >> 8);
  if (n > 0) {
    std::memcpy(out.data() + 6, payload.data(), n);
    const std::uint16_t crc = crc16(std::span<const std::uint8_t>(out.data() + 3, 3 + n));
    out[6 + n] = static_cast<std::uint8_t>(crc);
    out[7 + n] = static_cast<std::uint8_t>(crc >> 8);
  }
  return out;
}

/// Command: query the controller configuration.
inline std::vector<std::uint8_t> encode_query_controller_info() {
  return encode_packet(std::uint8_t(PacketId::controller_info), {});
}
/// Command: query the sensor configuration.
inline std::vector<std::uint8_t> encode_query_sensor_info() {
  return encode_packet(std::uint8_t(PacketId::sensor_info), {});
}
/// Command: query the configuration of matrix `index`.
inline std::vector<std::uint8_t> encode_query_matrix_info(std::uint8_t index) {
  const std::uint8_t p[1] = {index};
  return encode_packet(std::uint8_t(PacketId::matrix_info), p);
}
/// Command: configure acquisition. `acquire` starts streaming (bit 7), `rle` asks for
/// run-length encoded frames (bit 0); `rate` 0 with `acquire` false stops the stream.
inline std::vector<std::uint8_t> encode_set_acquisition(std::uint16_t rate, bool acquire,
                                                        bool rle) {
  const std::uint8_t flags =
      static_cast<std::uint8_t>((acquire ? 0x80 : 0x00) | (rle ? 0x01 : 0x00));
  const std::uint8_t p[3] = {flags, static_cast<std::uint8_t>(rate),
                             static_cast<std::uint8_t>(rate >> 8)};
  return encode_packet(std::uint8_t(PacketId::acquisition), p);
}

/// What a Parser saw besides good packets. Nothing is dropped silently.
struct ParserStats {
  std::size_t packets = 0;        ///< packets with a valid CRC (or no payload)
  std::size_t crc_errors = 0;     ///< candidate packets whose CRC did not match
  std::size_t oversized = 0;      ///< candidate packets announcing more than max_payload
  std::size_t skipped_bytes = 0;  ///< bytes that were not part of a valid packet
};

/// Incremental packet parser: feed() any split of the byte stream; next() yields packets in
/// order. Resynchronises after garbage, a bad CRC or an oversized length by rescanning from the
/// byte after the rejected preamble, so a good packet right after a bad one is still found. A
/// run of more than three 0xAA bytes is read as garbage followed by a preamble (no packet id is
/// 0xAA).
/// Memory is bounded by max_payload plus the bytes of one feed().
class Parser {
 public:
  explicit Parser(std::size_t max_payload = kDefaultMaxPayload) : max_payload_(max_payload) {}

  /// Appends bytes and parses every complete packet in them.
  void feed(std::span<const std::uint8_t> bytes) {
    buf_.insert(buf_.end(), bytes.begin(), bytes.end());
    parse();
  }
  /// The next complete packet, if any.
  std::optional<Packet> next() {
    if (ready_.empty()) return std::nullopt;
    Packet p = std::move(ready_.front());
    ready_.pop_front();
    return p;
  }
  /// Number of complete packets waiting.
  std::size_t pending() const noexcept { return ready_.size(); }
  /// Bytes held that may begin a packet not yet complete.
  std::size_t buffered() const noexcept { return buf_.size() - pos_; }
  /// Forgets buffered bytes and queued packets (after a disconnect); keeps the statistics.
  void reset() {
    stats_.skipped_bytes += buffered();
    buf_.clear();
    pos_ = 0;
    ready_.clear();
  }
  /// What was seen so far.
  const ParserStats& stats() const noexcept { return stats_; }
  /// The length bound [bytes].
  std::size_t max_payload() const noexcept { return max_payload_; }

 private:
  void skip(std::size_t n) {
    pos_ += n;
    stats_.skipped_bytes += n;
  }
  void parse() {
    for (;;) {
      // Find the preamble.
      std::size_t avail = buf_.size() - pos_;
      std::size_t run = 0;
      std::size_t i = 0;
      while (i < avail && run < 3) {
        run = buf_[pos_ + i] == 0xAA ? run + 1 : 0;
        ++i;
      }
      if (run < 3) {  // keep a partial preamble at the end
        skip(avail - run);
        break;
      }
      skip(i - 3);
      avail = buf_.size() - pos_;
      if (avail < 6) break;
      if (buf_[pos_ + 3] == 0xAA) {  // a fourth preamble byte: no packet has id 0xAA
        skip(1);
        continue;
      }
      const std::size_t size = std::size_t(buf_[pos_ + 4]) | (std::size_t(buf_[pos_ + 5]) << 8);
      if (size > max_payload_) {
        ++stats_.oversized;
        skip(1);
        continue;
      }
      const std::size_t total = 6 + size + (size > 0 ? 2 : 0);
      if (avail < total) break;
      const std::span<const std::uint8_t> all(buf_.data() + pos_, total);
      if (size > 0) {
        const std::uint16_t want = crc16(all.subspan(3, 3 + size));
        const std::uint16_t got =
            static_cast<std::uint16_t>(all[6 + size] | (unsigned(all[7 + size]) << 8));
        if (want != got) {
          ++stats_.crc_errors;
          skip(1);
          continue;
        }
      }
      ready_.push_back(
          Packet{all[3], std::vector<std::uint8_t>(all.begin() + 6, all.begin() + 6 + long(size))});
      ++stats_.packets;
      pos_ += total;
    }
    if (pos_ > 0 && (pos_ >= buf_.size() || pos_ > 65536)) {
      buf_.erase(buf_.begin(), buf_.begin() + long(pos_));
      pos_ = 0;
    }
  }

  std::size_t max_payload_;
  std::vector<std::uint8_t> buf_;
  std::size_t pos_ = 0;
  std::deque<Packet> ready_;
  ParserStats stats_;
};

namespace detail {
class Reader {
 public:
  Reader(std::span<const std::uint8_t> p, const char* what) : p_(p), what_(what) {}
  template <class T>
  T get() {
    if (at_ + sizeof(T) > p_.size()) {
      throw ProtocolError(std::string(what_) + ": payload ends at byte " +
                          std::to_string(p_.size()) + ", field at byte " + std::to_string(at_) +
                          " needs " + std::to_string(sizeof(T)));
    }
    T v;
    std::memcpy(&v, p_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::size_t at() const { return at_; }

 private:
  std::span<const std::uint8_t> p_;
  const char* what_;
  std::size_t at_ = 0;
};

// Out of line: inlined into the small encoders below, vector::insert draws false
// -Wstringop-overflow / -Warray-bounds reports from GCC 12 at -O3, depending on what else the
// translation unit inlines. Speed is no concern here (messages of a few bytes).
[[gnu::noinline]] inline void put_bytes(std::vector<std::uint8_t>& out, const void* v,
                                        std::size_t n) {
  const auto* b = static_cast<const std::uint8_t*>(v);
  out.insert(out.end(), b, b + n);
}
template <class T>
void put(std::vector<std::uint8_t>& out, T v) {
  put_bytes(out, &v, sizeof(T));
}

inline void expect_size(std::span<const std::uint8_t> p, std::size_t lo, std::size_t hi,
                        const char* what) {
  if (p.size() < lo || p.size() > hi) {
    throw ProtocolError(std::string(what) + ": payload of " + std::to_string(p.size()) +
                        " bytes, expected " + std::to_string(lo) +
                        (hi != lo ? "-" + std::to_string(hi) : std::string()));
  }
}
}  // namespace detail

/// Controller configuration (reply to 0x01). The controller sends 18 bytes although the record
/// has 19 (SDHLibrary notes it): the last byte, the high byte of can_id, is then 0.
struct ControllerInfo {
  std::uint16_t error_code = 0;
  std::uint32_t serial_no = 0;
  std::uint8_t hw_version = 0;
  std::uint16_t sw_version = 0;
  std::uint8_t status_flags = 0;
  std::uint8_t feature_flags = 0;
  std::uint8_t senscon_type = 0;
  std::uint8_t active_interface = 0;
  std::uint32_t can_baudrate = 0;
  std::uint16_t can_id = 0;
};

/// Sensor configuration (reply to 0x02, 12 bytes).
struct SensorInfo {
  std::uint16_t error_code = 0;
  std::uint16_t matrices = 0;
  std::uint16_t generated_by = 0;
  std::uint8_t hw_revision = 0;
  std::uint32_t serial_no = 0;
  std::uint8_t feature_flags = 0;
};

/// One matrix's configuration (reply to 0x0B, 52 bytes). Lengths in mm as the device reports.
struct MatrixInfo {
  std::uint16_t error_code = 0;
  float texel_width = 0, texel_height = 0;  ///< [mm]
  std::uint16_t cells_x = 0, cells_y = 0;   ///< columns, rows
  std::array<std::uint8_t, 6> uid{};
  std::uint8_t hw_revision = 0;
  std::array<float, 3> center{};  ///< [mm]
  std::array<float, 3> theta{};   ///< [rad]
  float fullscale = 0;            ///< largest texel value
  std::uint8_t feature_flags = 0;
  /// Tactels of the matrix.
  std::size_t cells() const noexcept { return std::size_t(cells_x) * cells_y; }
};

/// Decodes a controller-info payload (18 or 19 bytes); throws ProtocolError otherwise.
inline ControllerInfo decode_controller_info(std::span<const std::uint8_t> p) {
  detail::expect_size(p, 18, 19, "controller info");
  detail::Reader r(p, "controller info");
  ControllerInfo c;
  c.error_code = r.get<std::uint16_t>();
  c.serial_no = r.get<std::uint32_t>();
  c.hw_version = r.get<std::uint8_t>();
  c.sw_version = r.get<std::uint16_t>();
  c.status_flags = r.get<std::uint8_t>();
  c.feature_flags = r.get<std::uint8_t>();
  c.senscon_type = r.get<std::uint8_t>();
  c.active_interface = r.get<std::uint8_t>();
  c.can_baudrate = r.get<std::uint32_t>();
  c.can_id = r.get<std::uint8_t>();
  if (p.size() == 19) c.can_id = static_cast<std::uint16_t>(c.can_id | (p[18] << 8));
  return c;
}

/// The 18-byte controller-info payload a controller sends (for emulators and tests).
inline std::vector<std::uint8_t> encode_controller_info(const ControllerInfo& c) {
  std::vector<std::uint8_t> o;
  detail::put(o, c.error_code);
  detail::put(o, c.serial_no);
  detail::put(o, c.hw_version);
  detail::put(o, c.sw_version);
  detail::put(o, c.status_flags);
  detail::put(o, c.feature_flags);
  detail::put(o, c.senscon_type);
  detail::put(o, c.active_interface);
  detail::put(o, c.can_baudrate);
  detail::put(o, static_cast<std::uint8_t>(c.can_id));  // 18 bytes, as the controller sends
  return o;
}

/// Decodes a sensor-info payload (12 bytes); throws ProtocolError otherwise.
inline SensorInfo decode_sensor_info(std::span<const std::uint8_t> p) {
  detail::expect_size(p, 12, 12, "sensor info");
  detail::Reader r(p, "sensor info");
  SensorInfo s;
  s.error_code = r.get<std::uint16_t>();
  s.matrices = r.get<std::uint16_t>();
  s.generated_by = r.get<std::uint16_t>();
  s.hw_revision = r.get<std::uint8_t>();
  s.serial_no = r.get<std::uint32_t>();
  s.feature_flags = r.get<std::uint8_t>();
  return s;
}

/// The 12-byte sensor-info payload.
inline std::vector<std::uint8_t> encode_sensor_info(const SensorInfo& s) {
  std::vector<std::uint8_t> o;
  detail::put(o, s.error_code);
  detail::put(o, s.matrices);
  detail::put(o, s.generated_by);
  detail::put(o, s.hw_revision);
  detail::put(o, s.serial_no);
  detail::put(o, s.feature_flags);
  return o;
}

/// Decodes a matrix-info payload (52 bytes, little-endian IEEE floats); throws ProtocolError
/// otherwise.
inline MatrixInfo decode_matrix_info(std::span<const std::uint8_t> p) {
  detail::expect_size(p, 52, 52, "matrix info");
  detail::Reader r(p, "matrix info");
  MatrixInfo m;
  m.error_code = r.get<std::uint16_t>();
  m.texel_width = r.get<float>();
  m.texel_height = r.get<float>();
  m.cells_x = r.get<std::uint16_t>();
  m.cells_y = r.get<std::uint16_t>();
  for (auto& b : m.uid) b = r.get<std::uint8_t>();
  (void)r.get<std::uint16_t>();  // reserved
  m.hw_revision = r.get<std::uint8_t>();
  for (auto& v : m.center) v = r.get<float>();
  for (auto& v : m.theta) v = r.get<float>();
  m.fullscale = r.get<float>();
  m.feature_flags = r.get<std::uint8_t>();
  return m;
}

/// The 52-byte matrix-info payload.
inline std::vector<std::uint8_t> encode_matrix_info(const MatrixInfo& m) {
  std::vector<std::uint8_t> o;
  detail::put(o, m.error_code);
  detail::put(o, m.texel_width);
  detail::put(o, m.texel_height);
  detail::put(o, m.cells_x);
  detail::put(o, m.cells_y);
  for (const auto b : m.uid) detail::put(o, b);
  detail::put(o, std::uint16_t{0});
  detail::put(o, m.hw_revision);
  for (const auto v : m.center) detail::put(o, v);
  for (const auto v : m.theta) detail::put(o, v);
  detail::put(o, m.fullscale);
  detail::put(o, m.feature_flags);
  return o;
}

/// The error code of an acknowledgement (2-byte payload; 0 is success).
inline std::uint16_t decode_error_code(std::span<const std::uint8_t> p) {
  detail::expect_size(p, 2, 2, "acknowledgement");
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}

/// A decoded tactile frame: the controller's timestamp and every tactel, matrix after matrix,
/// each row-major (cells_x per row).
struct RawFrame {
  std::uint32_t timestamp_ms = 0;  ///< controller clock [ms]
  std::uint8_t flags = 0;          ///< bit 0: the payload was RLE coded
  std::vector<std::uint16_t> texels;
};

/// Decodes a frame payload holding `cells` tactels, raw (u16 each) or RLE (u16 units: value in
/// the low 12 bits, repeat count in the high 4). Throws ProtocolError when the payload does not
/// hold exactly `cells` tactels.
inline RawFrame decode_frame(std::span<const std::uint8_t> p, std::size_t cells) {
  if (p.size() < 5) {
    throw ProtocolError("frame: payload of " + std::to_string(p.size()) +
                        " bytes, shorter than its 5-byte header");
  }
  RawFrame f;
  std::memcpy(&f.timestamp_ms, p.data(), 4);
  f.flags = p[4];
  f.texels.reserve(cells);
  const auto body = p.subspan(5);
  if (f.flags & 0x01) {
    if (body.size() % 2 != 0) {
      throw ProtocolError("frame: RLE body of " + std::to_string(body.size()) +
                          " bytes is not a whole number of 2-byte units");
    }
    for (std::size_t i = 0; i < body.size(); i += 2) {
      const unsigned unit = body[i] | (unsigned(body[i + 1]) << 8);
      const unsigned count = unit >> 12;
      if (f.texels.size() + count > cells) {
        throw ProtocolError("frame: RLE unit at byte " + std::to_string(5 + i) + " runs past " +
                            std::to_string(cells) + " tactels");
      }
      f.texels.insert(f.texels.end(), count, static_cast<std::uint16_t>(unit & 0x0FFFu));
    }
    if (f.texels.size() != cells) {
      throw ProtocolError("frame: RLE body holds " + std::to_string(f.texels.size()) +
                          " tactels, expected " + std::to_string(cells));
    }
  } else {
    if (body.size() != 2 * cells) {
      throw ProtocolError("frame: raw body of " + std::to_string(body.size()) +
                          " bytes, expected " + std::to_string(2 * cells) + " for " +
                          std::to_string(cells) + " tactels");
    }
    f.texels.resize(cells);
    std::memcpy(f.texels.data(), body.data(), body.size());
  }
  return f;
}

/// Encodes a frame payload (what a controller sends). RLE needs values <= 4095 and codes runs
/// of up to 15; throws std::invalid_argument for a larger value with `rle`.
inline std::vector<std::uint8_t> encode_frame(std::uint32_t timestamp_ms,
                                              std::span<const std::uint16_t> texels, bool rle) {
  std::vector<std::uint8_t> o;
  o.reserve(5 + 2 * texels.size());
  detail::put(o, timestamp_ms);
  detail::put(o, static_cast<std::uint8_t>(rle ? 1 : 0));
  if (!rle) {
    detail::put_bytes(o, texels.data(), 2 * texels.size());
    return o;
  }
  for (std::size_t i = 0; i < texels.size();) {
    const std::uint16_t v = texels[i];
    if (v > 0x0FFF) {
      throw std::invalid_argument("dsa::encode_frame: RLE value " + std::to_string(v) +
                                  " at tactel " + std::to_string(i) + " exceeds 4095");
    }
    std::size_t n = 1;
    while (n < 15 && i + n < texels.size() && texels[i + n] == v) ++n;
    detail::put(o, static_cast<std::uint16_t>(v | (n << 12)));
    i += n;
  }
  return o;
}

}  // namespace taxel::drivers::dsa
