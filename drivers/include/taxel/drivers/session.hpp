// SPDX-License-Identifier: MIT
// Recorded device sessions: a text file of time-stamped byte chunks in both directions, a
// transport that records another one into it, and a transport that replays it (checking what
// the host writes against the recording).
//
// Format (UTF-8 text, one chunk per line; blank lines and lines starting with '#' are ignored):
//   taxel-session 1
//   <seconds since start> <direction> <hex bytes>
// direction '>' is host to device, '<' device to host; hex is an even number of digits, any
// case, no separators. Example:
//   0.000000 > aaaaaa0300030000ff..
#pragma once

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "taxel/drivers/transport.hpp"
#include "taxel/io/file.hpp"

namespace taxel::drivers {

/// One chunk of a session.
struct SessionChunk {
  double time = 0.0;       ///< seconds since the session started
  bool to_device = false;  ///< true: host -> device ('>'); false: device -> host ('<')
  std::vector<std::uint8_t> bytes;
  std::uint64_t line = 0;  ///< line in the session file (0: not read from a file)
};

/// A malformed session file; the message names the source and line.
struct SessionError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

namespace detail {
inline std::vector<SessionChunk> parse_session_lines(std::string_view text,
                                                     const std::string& source,
                                                     std::vector<SessionChunk>* kept);
}  // namespace detail

/// A session file read up to its first malformed line.
struct SessionPrefix {
  std::vector<SessionChunk> chunks;  ///< every chunk before the first malformed line
  std::string error;                 ///< "<source>:<line>: <why>", or empty for a whole file
};

/// Parses a session from text, keeping every chunk before the first malformed line (a
/// recording cut short, or damaged near its end, still replays up to the damage); `error`
/// names the source, the line and what is wrong.
inline SessionPrefix parse_session_prefix(std::string_view text,
                                          const std::string& source = "<session>") {
  SessionPrefix result;
  try {
    result.chunks = detail::parse_session_lines(text, source, &result.chunks);
  } catch (const SessionError& e) {
    result.error = e.what();
  }
  return result;
}

/// Parses a session from text. Throws SessionError naming `source`, the line and what is wrong.
inline std::vector<SessionChunk> parse_session(std::string_view text,
                                               const std::string& source = "<session>") {
  return detail::parse_session_lines(text, source, nullptr);
}

namespace detail {
// Parses every line; on a malformed one throws SessionError, after moving the chunks parsed so
// far to *kept (when given).
inline std::vector<SessionChunk> parse_session_lines(std::string_view text,
                                                     const std::string& source,
                                                     std::vector<SessionChunk>* kept) {
  std::vector<SessionChunk> out;
  std::uint64_t line_no = 0;
  bool header = false;
  double last_time = 0.0;
  const auto fail = [&](const std::string& why) {
    if (kept != nullptr) *kept = std::move(out);
    throw SessionError(source + ":" + std::to_string(line_no) + ": " + why);
  };
  io::LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    line_no = lines.line_number();
    if (line.empty() || line.front() == '#') continue;
    if (!header) {
      if (line != "taxel-session 1") fail("expected the header 'taxel-session 1'");
      header = true;
      continue;
    }
    const std::size_t s1 = line.find(' ');
    const std::size_t s2 = s1 == std::string_view::npos ? s1 : line.find(' ', s1 + 1);
    if (s2 == std::string_view::npos) fail("expected '<seconds> <'>' or '<'> <hex>'");
    const std::string time_text(line.substr(0, s1));
    const std::string_view dir = line.substr(s1 + 1, s2 - s1 - 1);
    const std::string_view hex = line.substr(s2 + 1);
    SessionChunk c;
    c.line = line_no;
    char* stop = nullptr;
    c.time = std::strtod(time_text.c_str(), &stop);
    if (time_text.empty() || stop != time_text.c_str() + time_text.size() ||
        !std::isfinite(c.time) || c.time < 0) {
      fail("time '" + time_text + "' is not a finite number of seconds >= 0");
    }
    if (c.time < last_time) fail("time goes backwards");
    last_time = c.time;
    if (dir == ">") {
      c.to_device = true;
    } else if (dir != "<") {
      fail("direction must be '>' (to the device) or '<' (from it)");
    }
    if (hex.empty() || hex.size() % 2 != 0) fail("hex bytes must be a non-empty, even count");
    const auto nibble = [&](char ch, std::size_t at) -> unsigned {
      if (ch >= '0' && ch <= '9') return unsigned(ch - '0');
      if (ch >= 'a' && ch <= 'f') return unsigned(ch - 'a' + 10);
      if (ch >= 'A' && ch <= 'F') return unsigned(ch - 'A' + 10);
      fail("'" + std::string(1, ch) + "' at column " + std::to_string(s2 + 2 + at) +
           " is not a hex digit");
      return 0;
    };
    c.bytes.reserve(hex.size() / 2);
    for (std::size_t i = 0; i < hex.size(); i += 2)
      c.bytes.push_back(
          static_cast<std::uint8_t>(nibble(hex[i], i) << 4 | nibble(hex[i + 1], i + 1)));
    out.push_back(std::move(c));
  }
  if (!header) {
    line_no = 1;
    fail("empty: expected the header 'taxel-session 1'");
  }
  return out;
}
}  // namespace detail

/// Reads a session file. Throws SessionError (malformed) or taxel::IoError (unreadable).
inline std::vector<SessionChunk> read_session(const std::string& path) {
  return parse_session(io::read_file(path), path);
}

/// Reads a session file up to its first malformed line (see parse_session_prefix). Throws
/// taxel::IoError when the file cannot be read.
inline SessionPrefix read_session_prefix(const std::string& path) {
  return parse_session_prefix(io::read_file(path), path);
}

/// The text of a session.
inline std::string format_session(std::span<const SessionChunk> chunks) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out = "taxel-session 1\n";
  char time[32];
  for (const auto& c : chunks) {
    std::snprintf(time, sizeof time, "%.6f", c.time);
    out.append(time).append(c.to_device ? " > " : " < ");
    for (const std::uint8_t b : c.bytes) {
      out.push_back(kHex[b >> 4]);
      out.push_back(kHex[b & 15]);
    }
    out.push_back('\n');
  }
  return out;
}

/// Writes a session file whole or not at all (taxel::io::write_file); throws taxel::IoError.
inline void write_session(const std::string& path, std::span<const SessionChunk> chunks) {
  io::write_file(path, format_session(chunks));
}

/// Wraps a transport and records every chunk written and read, with its time.
template <Transport T>
class RecordingTransport {
 public:
  explicit RecordingTransport(T inner) : inner_(std::move(inner)) {}
  /// Forwarded to the wrapped transport.
  void open() { inner_.open(); }
  /// Forwarded to the wrapped transport.
  void close() { inner_.close(); }
  /// Forwarded to the wrapped transport.
  bool is_open() const { return inner_.is_open(); }
  /// Writes through and records the chunk.
  void write(std::span<const std::uint8_t> bytes, Timeout timeout) {
    inner_.write(bytes, timeout);
    chunks_.push_back({now(), true, {bytes.begin(), bytes.end()}});
  }
  /// Reads through and records what arrived.
  std::size_t read(std::span<std::uint8_t> into, Timeout timeout) {
    const std::size_t n = inner_.read(into, timeout);
    if (n > 0) chunks_.push_back({now(), false, {into.begin(), into.begin() + long(n)}});
    return n;
  }
  /// What was recorded so far.
  const std::vector<SessionChunk>& chunks() const noexcept { return chunks_; }
  /// The wrapped transport.
  T& inner() noexcept { return inner_; }

 private:
  double now() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }
  T inner_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::vector<SessionChunk> chunks_;
};

/// Plays a recorded session back as the device. The host's bytes must equal the recorded
/// host-to-device stream (a difference throws TransportError `mismatch` naming the chunk and
/// byte); reads return the recorded device-to-host stream in order, but never bytes recorded
/// after a host chunk that has not been written yet (a reply never comes before its command).
/// How reads and writes interleave may differ from the recording. At the end of the device
/// stream reads return 0, like a silent device; `finished()` tells when both streams are
/// consumed. `realtime` paces reads by the recorded times.
class ReplayTransport {
 public:
  explicit ReplayTransport(std::vector<SessionChunk> chunks, bool realtime = false)
      : chunks_(std::move(chunks)), realtime_(realtime) {
    host_ = next(0, true);
    dev_ = next(0, false);
  }
  /// Reads the session from a file (see read_session).
  static ReplayTransport from_file(const std::string& path, bool realtime = false) {
    return ReplayTransport(read_session(path), realtime);
  }

  /// Starts (or resumes) the replay.
  void open() {
    open_ = true;
    start_ = std::chrono::steady_clock::now();
  }
  /// Pauses the replay (the position is kept).
  void close() { open_ = false; }
  /// True between open() and close().
  bool is_open() const { return open_; }
  bool finished() const { return host_ >= chunks_.size() && dev_ >= chunks_.size(); }
  /// True when every recorded device-to-host byte has been read.
  bool device_finished() const { return dev_ >= chunks_.size(); }

  /// Why recorded device bytes remain unread, or "" when none do. Call when reads stop
  /// returning data: a device chunk that waits for host bytes the host never wrote means the
  /// host and the recording went out of step (for example a flipped direction marker). The
  /// replies to the recording's last host command (a stop the host has not sent yet) are not
  /// counted.
  std::string stall_reason() const {
    std::size_t last_host = chunks_.size();
    for (std::size_t i = chunks_.size(); i-- > 0;) {
      if (chunks_[i].to_device) {
        last_host = i;
        break;
      }
    }
    if (dev_ >= chunks_.size() || (last_host < chunks_.size() && dev_ > last_host)) return {};
    std::size_t left = chunks_[dev_].bytes.size() - dev_off_;
    for (std::size_t i = next(dev_ + 1, false); i < chunks_.size(); i = next(i + 1, false)) {
      left += chunks_[i].bytes.size();
    }
    std::string why = "replay out of step: " + std::to_string(left) +
                      " recorded device bytes were never read, from chunk " +
                      std::to_string(dev_ + 1) + where(dev_);
    if (host_ < dev_) {
      why += ", which follows host bytes (chunk " + std::to_string(host_ + 1) + where(host_) +
             ") that were never written; a direction marker may be wrong";
    }
    return why;
  }

  /// The session file's line of the device bytes read last (0 before any, or for chunks not
  /// read from a file): where to look when the device's reply does not parse.
  std::uint64_t last_read_line() const noexcept { return last_line_; }

  /// Checks `bytes` against the recorded host stream.
  void write(std::span<const std::uint8_t> bytes, Timeout) {
    if (!open_) throw TransportError(TransportErrorKind::not_open, "replay: not open");
    for (const std::uint8_t b : bytes) {
      if (host_ >= chunks_.size()) {
        throw TransportError(TransportErrorKind::mismatch,
                             "replay: the host wrote past the end of the recording");
      }
      const SessionChunk& c = chunks_[host_];
      if (c.bytes[host_off_] != b) {
        throw TransportError(TransportErrorKind::mismatch,
                             "replay: host byte differs from the recording at chunk " +
                                 std::to_string(host_ + 1) + ", byte " + std::to_string(host_off_));
      }
      if (++host_off_ == c.bytes.size()) {
        host_off_ = 0;
        host_ = next(host_ + 1, true);
      }
    }
  }
  /// The next recorded device bytes, if their command was written.
  std::size_t read(std::span<std::uint8_t> into, Timeout timeout) {
    if (!open_) throw TransportError(TransportErrorKind::not_open, "replay: not open");
    // Nothing to give: the end of the device stream, or its next bytes wait for a command.
    if (dev_ >= chunks_.size() || host_ < dev_ || into.empty()) {
      if (realtime_) std::this_thread::sleep_for(timeout);
      return 0;
    }
    const SessionChunk& c = chunks_[dev_];
    if (realtime_) {
      const auto due = start_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                    std::chrono::duration<double>(c.time));
      if (due > std::chrono::steady_clock::now() + timeout) {
        std::this_thread::sleep_for(timeout);
        return 0;
      }
      std::this_thread::sleep_until(due);
    }
    const std::size_t n = std::min(into.size(), c.bytes.size() - dev_off_);
    std::copy_n(c.bytes.begin() + long(dev_off_), n, into.begin());
    last_line_ = c.line;
    dev_off_ += n;
    if (dev_off_ == c.bytes.size()) {
      dev_off_ = 0;
      dev_ = next(dev_ + 1, false);
    }
    return n;
  }

 private:
  std::string where(std::size_t i) const {
    return chunks_[i].line > 0 ? ", line " + std::to_string(chunks_[i].line) : std::string();
  }
  std::size_t next(std::size_t i, bool to_device) const {
    while (i < chunks_.size() && chunks_[i].to_device != to_device) ++i;
    return i;
  }
  std::vector<SessionChunk> chunks_;
  bool realtime_;
  bool open_ = false;
  std::size_t host_ = 0, host_off_ = 0;  // next host chunk to be written, and the byte in it
  std::size_t dev_ = 0, dev_off_ = 0;    // next device chunk to be read, and the byte in it
  std::uint64_t last_line_ = 0;          // file line of the device bytes read last
  std::chrono::steady_clock::time_point start_;
};

static_assert(Transport<ReplayTransport>);

/// Why a replay that has stopped delivering frames did not play the whole recording, or ""
/// when it did: recorded device bytes never read (see ReplayTransport::stall_reason), a last
/// packet cut off (`unparsed_bytes` from the device's parser, e.g. DsaconDevice::
/// unparsed_bytes), and the malformed line that ended the file (`file_error` from
/// SessionPrefix). Tools report it and exit non-zero.
inline std::string replay_shortfall(const ReplayTransport& replay, std::size_t unparsed_bytes,
                                    const std::string& file_error = {}) {
  std::string why = replay.stall_reason();
  const auto add = [&why](const std::string& part) {
    if (!why.empty()) why += "; ";
    why += part;
  };
  if (unparsed_bytes > 0) {
    add("the last packet is cut off (" + std::to_string(unparsed_bytes) +
        " bytes of it were recorded)");
  }
  if (!file_error.empty()) add(file_error + " (the chunks before it were replayed)");
  return why;
}

/// Ends the replay of a recorded session once `device` (a DsaconDevice over a ReplayTransport)
/// delivers no more frames: returns why the replay fell short of the whole recording, or ""
/// when it played all of it (replay_shortfall's reasons, and a recording that ends before the
/// host's stop command: taxel-record stops the controller before it saves, so a recording cut
/// short, even at a line boundary, lacks it). Then closes the device.
template <class Device>
std::string finish_replay(Device& device, const std::string& file_error = {}) {
  std::string why = replay_shortfall(device.transport(), device.unparsed_bytes(), file_error);
  if (why.empty() && device.streaming()) {
    try {
      device.stop();
    } catch (const std::exception&) {
      why = "the recording ends before the host's stop command: it was cut short";
    }
  }
  device.close();
  return why;
}

}  // namespace taxel::drivers
