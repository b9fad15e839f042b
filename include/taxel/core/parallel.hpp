// SPDX-License-Identifier: MIT
// A parallel loop over independent items on standard threads: the batch work of taxel (folds of
// a cross-validation, rounds of the 5x2cv test) spreads over the cores without a dependency.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace taxel {

/// The number of threads that `threads` asks for: itself when > 0, else every core the system
/// reports (at least 1).
inline unsigned resolve_threads(unsigned threads) noexcept {
  if (threads > 0) return threads;
  return std::max(1u, std::thread::hardware_concurrency());
}

/// Calls fn(i) once for every i in [0, n), on up to `threads` threads (0: every core), the
/// calling thread included; items are handed out one at a time, so uneven items balance.
/// Returns when every call has returned. When calls throw, the remaining items are skipped and
/// the exception of the lowest item that threw is rethrown. `fn` must be safe to call
/// concurrently for different items; a result written to slot i of a presized container keeps
/// the outcome independent of the thread count. With one thread (or n <= 1) no thread starts.
template <class Fn>
void parallel_for(std::size_t n, unsigned threads, Fn&& fn) {
  const std::size_t workers = std::min<std::size_t>(resolve_threads(threads), n);
  if (workers <= 1) {
    for (std::size_t i = 0; i < n; ++i) fn(i);
    return;
  }
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::mutex mutex;
  std::exception_ptr error;
  std::size_t error_item = n;
  const auto work = [&] {
    for (std::size_t i; !failed.load(std::memory_order_relaxed) &&
                        (i = next.fetch_add(1, std::memory_order_relaxed)) < n;) {
      try {
        fn(i);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(mutex);
        if (i < error_item) {
          error_item = i;
          error = std::current_exception();
        }
        failed.store(true, std::memory_order_relaxed);
      }
    }
  };
  std::vector<std::jthread> pool;
  pool.reserve(workers - 1);
  for (std::size_t t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  pool.clear();  // joins
  if (error) std::rethrow_exception(error);
}

}  // namespace taxel
