// SPDX-License-Identifier: MIT
// Exceptions for bad file and device input, carrying where the input went wrong.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

namespace taxel {

/// `text` with control characters (a NUL, a line break, an escape, DEL) shown as `\\xNN`, so
/// that text quoted from an input cannot cut or split a one-line message.
inline std::string printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u != 0x7f) {
      out.push_back(c);
    } else {
      out.append("\\x").push_back(kHex[u >> 4]);
      out.push_back(kHex[u & 15]);
    }
  }
  return out;
}

/// A file or stream could not be read or written, or its content is malformed.
/// `what()` reads "<source>:<line>: <reason>" or "<source>: byte <offset>: <reason>", with
/// control characters shown as `\\xNN` so that it stays one whole line.
class IoError : public std::runtime_error {
 public:
  /// `source` names the file (or stream); `line` is 1-based; `byte_offset` is 0-based.
  IoError(std::string source, std::string reason, std::optional<std::uint64_t> line = {},
          std::optional<std::uint64_t> byte_offset = {})
      : std::runtime_error(format(source, reason, line, byte_offset)),
        source_(std::move(source)),
        reason_(std::move(reason)),
        line_(line),
        byte_offset_(byte_offset) {}

  /// The file or stream name.
  [[nodiscard]] const std::string& source() const noexcept { return source_; }
  /// What was wrong, without the location.
  [[nodiscard]] const std::string& reason() const noexcept { return reason_; }
  /// 1-based line of the error in a text input, if known.
  [[nodiscard]] std::optional<std::uint64_t> line() const noexcept { return line_; }
  /// 0-based byte offset of the error, if known.
  [[nodiscard]] std::optional<std::uint64_t> byte_offset() const noexcept { return byte_offset_; }

 private:
  static std::string format(const std::string& source, const std::string& reason,
                            std::optional<std::uint64_t> line,
                            std::optional<std::uint64_t> byte_offset) {
    // append() rather than operator+: GCC 12 misreports -Wstringop-overflow on the latter.
    std::string s;
    s.reserve(source.size() + reason.size() + 32);
    s.append(source);
    if (line) s.append(":").append(std::to_string(*line));
    if (byte_offset) s.append(": byte ").append(std::to_string(*byte_offset));
    s.append(": ").append(reason);
    // Control bytes quoted from an input (a NUL, a line break, an escape) are shown as \xNN:
    // a NUL would cut the message where C strings end, a line break would split it.
    return printable(s);
  }

  std::string source_;
  std::string reason_;
  std::optional<std::uint64_t> line_;
  std::optional<std::uint64_t> byte_offset_;
};

/// A device answered with bytes that violate its protocol (bad checksum, unexpected packet,
/// impossible length, error code). `what()` reads "<device>: <reason>".
class ProtocolError : public std::runtime_error {
 public:
  /// `device` names the device or transport; `packet_id` is the offending packet, if known.
  ProtocolError(std::string device, std::string reason, std::optional<int> packet_id = {})
      : std::runtime_error(device + ": " + reason),
        device_(std::move(device)),
        packet_id_(packet_id) {}

  /// The device or transport name.
  [[nodiscard]] const std::string& device() const noexcept { return device_; }
  /// The packet identifier the error concerns, if known.
  [[nodiscard]] std::optional<int> packet_id() const noexcept { return packet_id_; }

 private:
  std::string device_;
  std::optional<int> packet_id_;
};

}  // namespace taxel
