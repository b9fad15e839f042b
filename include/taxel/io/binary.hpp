// SPDX-License-Identifier: MIT
// Little-endian binary fields for taxel's own file formats (optical calibrations, learned
// models): a writer that appends them to a string, and a reader that refuses bytes cut short,
// counts beyond what the bytes can hold and values that are not finite, naming the field.
#pragma once

#include <Eigen/Core>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "taxel/core/error.hpp"

namespace taxel::io {

/// Appends an arithmetic value's bytes to `out` (little-endian hosts only).
template <class T>
void put_le(std::string& out, T v) {
  static_assert(std::is_arithmetic_v<T>, "arithmetic values only");
  static_assert(std::endian::native == std::endian::little, "little-endian hosts only");
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

/// Appends fields to `out`, little-endian.
class BinaryWriter {
 public:
  /// Bytes written so far.
  std::string out;

  /// One arithmetic value as its bytes.
  template <class T>
  void put(T v) {
    put_le<T>(out, v);
  }
  /// A count (uint64) then the values.
  template <class T>
  void put_vector(const std::vector<T>& v) {
    put<std::uint64_t>(v.size());
    for (const T& x : v) put<T>(x);
  }
  /// Rows and columns (uint64), then the coefficients row by row.
  template <class Derived>
  void put_matrix(const Eigen::MatrixBase<Derived>& m) {
    put<std::uint64_t>(static_cast<std::uint64_t>(m.rows()));
    put<std::uint64_t>(static_cast<std::uint64_t>(m.cols()));
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) put<double>(m(r, c));
    }
  }
};

/// Reads fields from `bytes`, starting at `at`; errors are IoError naming `source`, the field
/// and the byte offset.
class BinaryReader {
 public:
  /// The bytes read.
  std::string_view bytes;
  /// Named in errors (a file name, or what the bytes are).
  std::string source;
  /// Offset of the next field.
  std::size_t at = 0;

  /// An IoError at the current offset.
  [[noreturn]] void fail(const std::string& what) const {
    throw IoError(source, what, std::nullopt, at);
  }
  /// One arithmetic value; IoError when the bytes end first.
  template <class T>
  T get(const char* what) {
    static_assert(std::is_arithmetic_v<T>, "arithmetic values only");
    if (bytes.size() - at < sizeof(T)) fail(std::string("cut short in ") + what);
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  /// A float64 that must be finite.
  double finite(const char* what) {
    const double v = get<double>(what);
    if (!std::isfinite(v)) {
      at -= sizeof(double);
      fail(std::string(what) + " is not finite");
    }
    return v;
  }
  /// A uint64 count of items of `item_bytes` each, refused when the bytes left cannot hold
  /// that many (so that a damaged count never allocates).
  std::size_t count(const char* what, std::size_t item_bytes) {
    const auto n = get<std::uint64_t>(what);
    const std::size_t left = bytes.size() - at;
    if (item_bytes > 0 && n > left / item_bytes) {
      at -= sizeof(std::uint64_t);
      fail(std::string(what) + ": a count of " + std::to_string(n) + " is more than the " +
           std::to_string(left) + " bytes left hold");
    }
    return static_cast<std::size_t>(n);
  }
  /// A vector written by BinaryWriter::put_vector; doubles must be finite.
  template <class T>
  std::vector<T> get_vector(const char* what) {
    std::vector<T> v(count(what, sizeof(T)));
    for (T& x : v) {
      if constexpr (std::is_floating_point_v<T>) {
        x = static_cast<T>(finite(what));
      } else {
        x = get<T>(what);
      }
    }
    return v;
  }
  /// A matrix written by BinaryWriter::put_matrix into `m` (any dense Eigen matrix type);
  /// coefficients must be finite, and a vector type must get one column.
  template <class M>
  void get_matrix(M& m, const char* what) {
    const auto rows = get<std::uint64_t>(what);
    const auto cols = get<std::uint64_t>(what);
    const std::size_t left = bytes.size() - at;
    if (rows > (1u << 31) || cols > (1u << 31) || (cols > 0 && rows > left / 8 / cols)) {
      fail(std::string(what) + ": " + std::to_string(rows) + " x " + std::to_string(cols) +
           " is more than the bytes left hold");
    }
    if ((M::ColsAtCompileTime == 1 && cols != 1) || (M::RowsAtCompileTime == 1 && rows != 1)) {
      fail(std::string(what) + " is not a vector");
    }
    m.resize(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      for (Eigen::Index c = 0; c < m.cols(); ++c) m.coeffRef(r, c) = finite(what);
    }
  }
  /// Whether every byte has been read.
  [[nodiscard]] bool done() const noexcept { return at == bytes.size(); }
};

}  // namespace taxel::io
