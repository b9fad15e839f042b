// SPDX-License-Identifier: MIT
// Outcome of a numerical algorithm: a status code plus a human-readable message.
#pragma once

#include <string>
#include <string_view>
#include <utility>

namespace taxel {

/// How an algorithm ended. Only `ok` means the result can be used without further checks.
enum class Status {
  ok,             ///< converged / succeeded
  not_converged,  ///< stopped at an iteration limit; the result is the last iterate
  degenerate,     ///< the input does not determine a unique answer (too few or collinear points)
  invalid_input,  ///< non-finite values, mismatched sizes or out-of-range parameters
};

/// Lower-case name of a status, as spelled in the enum.
constexpr std::string_view to_string(Status s) noexcept {
  switch (s) {
    case Status::ok:
      return "ok";
    case Status::not_converged:
      return "not_converged";
    case Status::degenerate:
      return "degenerate";
    case Status::invalid_input:
      return "invalid_input";
  }
  return "unknown";
}

/// A status with the reason; the base of every `<Thing>Result` in taxel.
struct Outcome {
  Status status = Status::ok;  ///< how the algorithm ended
  std::string message;         ///< why, when status != ok; empty otherwise

  /// True when status is `ok`.
  [[nodiscard]] bool ok() const noexcept { return status == Status::ok; }
  /// True when status is `ok`.
  explicit operator bool() const noexcept { return ok(); }
};

/// A value together with the outcome that produced it. `value` is meaningful only when `ok()`
/// or when the algorithm documents what it holds otherwise (e.g. the last iterate).
template <class T>
struct Result : Outcome {
  T value{};  ///< the computed value

  /// A successful result.
  static Result success(T v) { return Result{{Status::ok, {}}, std::move(v)}; }
  /// A failed result with its reason; `value` is value-initialised.
  static Result failure(Status s, std::string why) { return Result{{s, std::move(why)}, T{}}; }
};

}  // namespace taxel
