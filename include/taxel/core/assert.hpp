// SPDX-License-Identifier: MIT
// TAXEL_ASSERT: checks for caller bugs, active in debug builds, with a replaceable handler.
#pragma once

#include <atomic>
#include <stdexcept>
#include <string>

namespace taxel {

/// Thrown by the default assertion handler. A failed assertion is a bug in the calling code.
class AssertionError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// Called on a failed TAXEL_ASSERT. It must not return normally (throw or abort).
using AssertHandler = void (*)(const char* expression, const char* message, const char* file,
                               int line);

namespace detail {
[[noreturn]] inline void default_assert_handler(const char* expression, const char* message,
                                                const char* file, int line) {
  throw AssertionError(std::string(file) + ":" + std::to_string(line) + ": assertion `" +
                       expression + "` failed: " + message);
}
inline std::atomic<AssertHandler>& assert_handler_slot() noexcept {
  static std::atomic<AssertHandler> slot{&default_assert_handler};
  return slot;
}
[[noreturn]] inline void assert_failed(const char* expression, const char* message,
                                       const char* file, int line) {
  assert_handler_slot().load(std::memory_order_acquire)(expression, message, file, line);
  // A handler that returns breaks the contract; stop rather than continue in a broken state.
  std::terminate();
}
}  // namespace detail

/// Installs `handler` (nullptr restores the default, which throws AssertionError) and returns
/// the previous one. Thread-safe.
inline AssertHandler set_assert_handler(AssertHandler handler) noexcept {
  return detail::assert_handler_slot().exchange(handler ? handler : &detail::default_assert_handler,
                                                std::memory_order_acq_rel);
}

}  // namespace taxel

/// TAXEL_ASSERT(condition, message): active unless NDEBUG is defined; define
/// TAXEL_ENABLE_ASSERTS to keep it in release builds or TAXEL_DISABLE_ASSERTS to drop it always.
#if (!defined(NDEBUG) || defined(TAXEL_ENABLE_ASSERTS)) && !defined(TAXEL_DISABLE_ASSERTS)
#define TAXEL_ASSERTS_ACTIVE 1
#define TAXEL_ASSERT(condition, message)                                       \
  do {                                                                         \
    if (!(condition)) {                                                        \
      ::taxel::detail::assert_failed(#condition, message, __FILE__, __LINE__); \
    }                                                                          \
  } while (false)
#else
#define TAXEL_ASSERTS_ACTIVE 0
#define TAXEL_ASSERT(condition, message) \
  do {                                   \
  } while (false && (condition))
#endif
