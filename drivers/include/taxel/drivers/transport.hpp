// SPDX-License-Identifier: MIT
// Byte transports for device drivers: the concept, its errors, and an in-memory loopback pair
// for tests and emulators.
#pragma once

#include <algorithm>
#include <chrono>
#include <concepts>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

namespace taxel::drivers {

/// Why a transport failed.
enum class TransportErrorKind {
  not_open,      ///< used before open() or after close()
  disconnected,  ///< the device went away (unplugged, peer closed)
  timeout,       ///< a write did not complete in time
  io,            ///< any other operating-system or library error
  mismatch,      ///< a replayed session expected other bytes
};

/// A transport failure; `kind()` says which.
class TransportError : public std::runtime_error {
 public:
  TransportError(TransportErrorKind kind, const std::string& what)
      : std::runtime_error(what), kind_(kind) {}
  /// Which failure.
  TransportErrorKind kind() const noexcept { return kind_; }

 private:
  TransportErrorKind kind_;
};

using Timeout = std::chrono::milliseconds;

/// A byte stream to a device. `read` waits up to `timeout` for at least one byte and returns
/// how many it stored (0: nothing arrived in time); `write` sends all bytes or throws.
/// Both throw TransportError (disconnected, io, ...). `open` may be called again after a
/// disconnect to reconnect.
template <class T>
concept Transport = requires(T& t, std::span<const std::uint8_t> out, std::span<std::uint8_t> in,
                             Timeout timeout) {
  {t.open()};
  {t.close()};
  { t.is_open() } -> std::convertible_to<bool>;
  {t.write(out, timeout)};
  { t.read(in, timeout) } -> std::same_as<std::size_t>;
};

/// One end of an in-memory byte pipe. `LoopbackTransport::pair()` makes two connected ends:
/// what one writes, the other reads. Thread-safe. `disconnect()` (from either end) makes both
/// ends fail with `disconnected` and drops bytes in flight until `open()` reconnects them.
class LoopbackTransport {
 public:
  /// Two connected ends.
  static std::pair<LoopbackTransport, LoopbackTransport> pair() {
    auto shared = std::make_shared<Shared>();
    return {LoopbackTransport(shared, 0), LoopbackTransport(shared, 1)};
  }

  /// Opens this end; reconnects a disconnected pair.
  void open() {
    std::lock_guard lock(s_->m);
    s_->connected = true;
    s_->open[side_] = true;
  }
  /// Closes this end (a blocked read on it returns with `not_open`).
  void close() {
    std::lock_guard lock(s_->m);
    s_->open[side_] = false;
    s_->cv.notify_all();
  }
  /// True when this end is open and the pair connected.
  bool is_open() const {
    std::lock_guard lock(s_->m);
    return s_->open[side_] && s_->connected;
  }
  /// Breaks the link, as an unplugged cable would.
  void disconnect() {
    std::lock_guard lock(s_->m);
    s_->connected = false;
    s_->queue[0].clear();
    s_->queue[1].clear();
    s_->cv.notify_all();
  }

  /// Queues `bytes` for the other end (never blocks).
  void write(std::span<const std::uint8_t> bytes, Timeout = Timeout(0)) {
    std::lock_guard lock(s_->m);
    check();
    auto& q = s_->queue[1 - side_];
    q.insert(q.end(), bytes.begin(), bytes.end());
    s_->cv.notify_all();
  }
  /// Waits up to `timeout` for bytes from the other end; returns how many were stored.
  std::size_t read(std::span<std::uint8_t> into, Timeout timeout) {
    std::unique_lock lock(s_->m);
    check();
    auto& q = s_->queue[side_];
    s_->cv.wait_for(lock, timeout,
                    [&] { return !q.empty() || !s_->connected || !s_->open[side_]; });
    check();
    const std::size_t n = std::min(into.size(), q.size());
    std::copy_n(q.begin(), n, into.begin());
    q.erase(q.begin(), q.begin() + long(n));
    return n;
  }

 private:
  struct Shared {
    mutable std::mutex m;
    std::condition_variable cv;
    std::deque<std::uint8_t> queue[2];  // bytes waiting to be read by side i
    bool open[2] = {false, false};
    bool connected = true;
  };
  LoopbackTransport(std::shared_ptr<Shared> s, int side) : s_(std::move(s)), side_(side) {}
  void check() const {
    if (!s_->open[side_]) throw TransportError(TransportErrorKind::not_open, "loopback: not open");
    if (!s_->connected) {
      throw TransportError(TransportErrorKind::disconnected, "loopback: disconnected");
    }
  }
  std::shared_ptr<Shared> s_;
  int side_;
};

static_assert(Transport<LoopbackTransport>);

}  // namespace taxel::drivers
