// SPDX-License-Identifier: MIT
// A serial-port transport (POSIX termios): raw 8N1 at a given baud rate, timeouts by poll().
// The DSACON32m talks 115200 baud over RS-232 or a USB-serial adapter (/dev/ttyUSB0,
// /dev/ttyACM0).
#pragma once

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <utility>

#include "taxel/drivers/transport.hpp"

namespace taxel::drivers {

/// A serial port in raw mode. Move-only; closes on destruction.
class SerialTransport {
 public:
  /// A port at `path` (opened by open()) at `baud` bits per second.
  explicit SerialTransport(std::string path, unsigned baud = 115200)
      : path_(std::move(path)), baud_(baud) {}
  SerialTransport(SerialTransport&& o) noexcept
      : path_(std::move(o.path_)), baud_(o.baud_), fd_(std::exchange(o.fd_, -1)) {}
  SerialTransport& operator=(SerialTransport&& o) noexcept {
    if (this != &o) {
      close();
      path_ = std::move(o.path_);
      baud_ = o.baud_;
      fd_ = std::exchange(o.fd_, -1);
    }
    return *this;
  }
  SerialTransport(const SerialTransport&) = delete;
  SerialTransport& operator=(const SerialTransport&) = delete;
  ~SerialTransport() { close(); }

  /// Opens the port: raw mode, 8 data bits, no parity, 1 stop bit, no flow control.
  void open() {
    close();
    const speed_t speed = to_speed(baud_);
    fd_ = ::open(path_.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    if (fd_ < 0) fail(TransportErrorKind::io, "cannot open");
    termios tio{};
    if (::tcgetattr(fd_, &tio) != 0) fail_and_close("is not a serial port (tcgetattr)");
    ::cfmakeraw(&tio);
    tio.c_cflag |= CLOCAL | CREAD;
    tio.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | CRTSCTS);
    tio.c_cc[VMIN] = 0;
    tio.c_cc[VTIME] = 0;
    if (::cfsetispeed(&tio, speed) != 0 || ::cfsetospeed(&tio, speed) != 0 ||
        ::tcsetattr(fd_, TCSANOW, &tio) != 0) {
      fail_and_close("cannot set raw mode at " + std::to_string(baud_) + " baud");
    }
    ::tcflush(fd_, TCIOFLUSH);
  }
  /// Closes the port (idempotent).
  void close() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
  /// True between open() and close() or a lost device.
  bool is_open() const noexcept { return fd_ >= 0; }

  /// Writes every byte within `timeout` or throws (timeout, disconnected).
  void write(std::span<const std::uint8_t> bytes, Timeout timeout) {
    require_open();
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (!bytes.empty()) {
      const ssize_t n = ::write(fd_, bytes.data(), bytes.size());
      if (n > 0) {
        bytes = bytes.subspan(std::size_t(n));
        continue;
      }
      if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) lost("write");
      const auto left = deadline - std::chrono::steady_clock::now();
      if (left <= std::chrono::steady_clock::duration::zero()) {
        throw TransportError(TransportErrorKind::timeout, path_ + ": write timed out");
      }
      wait(POLLOUT, std::chrono::duration_cast<Timeout>(left));
    }
  }

  /// Reads what arrives within `timeout` (0 bytes on timeout); a hang-up throws disconnected.
  std::size_t read(std::span<std::uint8_t> into, Timeout timeout) {
    require_open();
    if (into.empty()) return 0;
    if (!wait(POLLIN, timeout)) return 0;
    const ssize_t n = ::read(fd_, into.data(), into.size());
    if (n > 0) return std::size_t(n);
    if (n == 0) {
      errno = 0;
      lost("read (end of file)");
    }
    if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) return 0;
    lost("read");
  }

  /// The device path.
  const std::string& path() const noexcept { return path_; }

 private:
  static speed_t to_speed(unsigned baud) {
    switch (baud) {
      case 9600:
        return B9600;
      case 19200:
        return B19200;
      case 38400:
        return B38400;
      case 57600:
        return B57600;
      case 115200:
        return B115200;
      case 230400:
        return B230400;
      case 460800:
        return B460800;
      case 921600:
        return B921600;
      default:
        throw TransportError(TransportErrorKind::io,
                             "serial: unsupported baud rate " + std::to_string(baud));
    }
  }
  // Waits for `events`; true when ready, false on timeout. Hang-up or error: disconnected.
  bool wait(short events, Timeout timeout) {
    pollfd p{fd_, events, 0};
    int r;
    do {
      r = ::poll(&p, 1, static_cast<int>(timeout.count()));
    } while (r < 0 && errno == EINTR);
    if (r < 0) fail(TransportErrorKind::io, "poll");
    if (r == 0) return false;
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) {
      if (p.revents & events) return true;  // drain what is left before the hang-up
      lost("poll (hang-up)");
    }
    return true;
  }
  void require_open() const {
    if (fd_ < 0) throw TransportError(TransportErrorKind::not_open, path_ + ": not open");
  }
  [[noreturn]] void lost(const char* where) {
    const int e = errno;
    close();
    throw TransportError(TransportErrorKind::disconnected,
                         path_ + ": device lost in " + where +
                             (e != 0 ? std::string(": ") + std::strerror(e) : std::string()));
  }
  [[noreturn]] void fail(TransportErrorKind kind, const std::string& what) const {
    throw TransportError(kind, path_ + ": " + what + ": " + std::strerror(errno));
  }
  [[noreturn]] void fail_and_close(const std::string& what) {
    const int e = errno;
    close();
    throw TransportError(TransportErrorKind::io, path_ + ": " + what + ": " + std::strerror(e));
  }

  std::string path_;
  unsigned baud_;
  int fd_ = -1;
};

static_assert(Transport<SerialTransport>);

}  // namespace taxel::drivers
