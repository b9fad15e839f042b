// SPDX-License-Identifier: MIT
// NumPy .npy arrays: the format's one reader (parse_npy_header, also behind io/image.hpp's
// pressure images) and the arrays of integer readings, a stack of tactile frames as numpy saves
// it (np.save("readings.npy", frames), frames of shape (frames, rows, cols) or
// (frames, pads, rows, cols)). Format: NEP 1, "A simple file format for NumPy arrays",
// versions 1.0, 2.0 and 3.0.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/io/file.hpp"

namespace taxel::io {

/// An n-dimensional array of unsigned 16-bit values in C (row-major) order.
struct NpyU16 {
  std::vector<std::size_t> shape;     ///< dimensions, outermost first
  std::vector<std::uint16_t> values;  ///< product(shape) values
};

/// What a .npy file's header says about its array, and where the values start: the one reader
/// of the format behind parse_npy_u16 (readings) and io/image.hpp's parse_npy (images).
struct NpyArray {
  char kind = 'u';                   ///< 'u' unsigned, 'i' signed integer, 'f' floating point
  int width = 1;                     ///< bytes per value: 1, 2, 4 or 8
  bool big_endian = false;           ///< byte order of the values
  bool fortran_order = false;        ///< stored column-major (the first index varies fastest)
  std::vector<std::uint64_t> shape;  ///< dimensions, outermost first
  std::uint64_t count = 1;           ///< number of values, the product of shape
  std::size_t data_at = 0;           ///< byte offset of the first value
  std::size_t shape_at = 0;          ///< byte offset of the shape in the header

  /// The value stored `k`-th in the file, converted to double (exact for integers below 2^53).
  [[nodiscard]] double value(std::string_view bytes, std::uint64_t k) const noexcept {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data()) + data_at +
                    k * static_cast<std::uint64_t>(width);
    std::uint64_t raw = 0;
    for (int b = 0; b < width; ++b) {
      raw |= std::uint64_t{p[b]} << (8 * (big_endian ? width - 1 - b : b));
    }
    if (kind == 'u') return static_cast<double>(raw);
    if (kind == 'i') {
      const int shift = 64 - 8 * width;  // sign-extend
      return static_cast<double>(static_cast<std::int64_t>(raw << shift) >> shift);
    }
    if (width == 4)
      return static_cast<double>(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
    return std::bit_cast<double>(raw);
  }

  /// The row-major (C order, numpy's `flat`) index of the value stored `k`-th in the file.
  [[nodiscard]] std::uint64_t flat_index(std::uint64_t k) const noexcept {
    if (!fortran_order) return k;
    std::uint64_t index = 0, stride = 1;
    for (std::size_t d = shape.size(); d-- > 0;) stride *= shape[d];
    for (const std::uint64_t n : shape) {  // the first dimension varies fastest in the file
      stride /= n;
      index += (k % n) * stride;
      k /= n;
    }
    return index;
  }
};

namespace detail_npy {

[[noreturn]] inline void fail(const std::string& source, std::size_t at, const std::string& why) {
  throw IoError(source, why, std::nullopt, at);
}

// The value of `key` in the header dict (Python literal), up to the next top-level ',' or '}'
// (a tuple kept whole), and its byte offset in the file (`base` is the header's).
inline std::pair<std::string_view, std::size_t> dict_value(std::string_view header,
                                                           std::size_t base, std::string_view key,
                                                           const std::string& source) {
  std::size_t at = std::string_view::npos;
  for (const char q : {'\'', '"'}) {
    std::string quoted;  // append(): GCC 12 misreports -Wrestrict on "'" + std::string
    quoted.append(1, q).append(key).append(1, q);
    at = header.find(quoted);
    if (at != std::string_view::npos) {
      at += quoted.size();
      break;
    }
  }
  if (at == std::string_view::npos) fail(source, base, "header has no '" + std::string(key) + "'");
  at = header.find(':', at);
  if (at == std::string_view::npos) {
    fail(source, base, "header: no ':' after '" + std::string(key) + "'");
  }
  ++at;
  while (at < header.size() && header[at] == ' ') ++at;
  std::size_t end = at;
  int depth = 0;
  while (end < header.size()) {
    const char c = header[end];
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (depth == 0 && (c == ',' || c == '}')) break;
    ++end;
  }
  if (end >= header.size()) {
    fail(source, base + at, "header: unterminated value of '" + std::string(key) + "'");
  }
  std::string_view v = header.substr(at, end - at);
  while (!v.empty() && v.back() == ' ') v.remove_suffix(1);
  return {v, base + at};
}

// The version 1.0 header of an array of `descr` ("<u2") and `shape` ("(3, 4)"), padded so
// that the data start at a multiple of 64 bytes, as numpy writes it.
inline std::string header_v1(std::string_view descr, std::string_view shape) {
  std::string dict;  // append(): GCC 12 misreports -Wstringop-overflow on operator+ here
  dict.append("{'descr': '").append(descr).append("', 'fortran_order': False, 'shape': ");
  dict.append(shape).append(", }");
  const std::size_t total = 10 + dict.size() + 1;
  dict.append((64 - total % 64) % 64, ' ');
  dict.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(dict.size() & 0xFF));
  out.push_back(static_cast<char>(dict.size() >> 8));
  return out.append(dict);
}

}  // namespace detail_npy

/// Reads the header of a .npy file (format versions 1.0, 2.0 and 3.0): dtype u1, u2, u4, u8,
/// i1, i2, i4, i8, f4 or f8 in either byte order, C or Fortran order, any number of
/// dimensions. Checks that exactly the values the shape holds follow the header, and that they
/// are at most `max_count`. Throws IoError naming the file and the byte of the problem.
inline NpyArray parse_npy_header(std::string_view bytes, const std::string& source,
                                 std::uint64_t max_count) {
  using detail_npy::fail;
  if (bytes.size() < 10 || bytes.substr(0, 6) != std::string_view("\x93NUMPY", 6)) {
    fail(source, 0, "not a .npy file: the magic string \\x93NUMPY is missing");
  }
  const auto major = static_cast<unsigned char>(bytes[6]);
  std::size_t header_len = 0, at = 10;
  if (major == 1) {
    header_len = static_cast<unsigned char>(bytes[8]) |
                 (std::size_t{static_cast<unsigned char>(bytes[9])} << 8);
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) fail(source, 8, "truncated header length");
    for (int k = 0; k < 4; ++k) {
      header_len |= std::size_t{static_cast<unsigned char>(bytes[8 + std::size_t(k)])} << (8 * k);
    }
    at = 12;
  } else {
    fail(source, 6, "unsupported .npy format version " + std::to_string(major));
  }
  if (header_len > bytes.size() - at) {
    fail(source, at,
         "truncated header: the header of " + std::to_string(header_len) +
             " bytes runs past the end of the file");
  }
  const std::string_view header = bytes.substr(at, header_len);
  NpyArray a;
  a.data_at = at + header_len;

  const auto [descr, descr_at] = detail_npy::dict_value(header, at, "descr", source);
  if (descr.size() < 5 || (descr.front() != '\'' && descr.front() != '"') ||
      descr.back() != descr.front()) {
    fail(source, descr_at,
         "descr " + std::string(descr) + " is not a simple dtype string such as '<u2'");
  }
  const std::string_view dtype = descr.substr(1, descr.size() - 2);
  a.kind = dtype[1];
  a.width = dtype.size() == 3 && dtype[2] >= '1' && dtype[2] <= '8' ? dtype[2] - '0' : 0;
  const bool known = (a.kind == 'u' || a.kind == 'i')
                         ? (a.width == 1 || a.width == 2 || a.width == 4 || a.width == 8)
                         : (a.kind == 'f' && (a.width == 4 || a.width == 8));
  if (!known) {
    fail(source, descr_at,
         "unsupported dtype '" + std::string(dtype) +
             "': use u1, i1, u2, i2, u4, i4, u8, i8, f4 or f8");
  }
  const char order = dtype[0];
  if (order != '<' && order != '>' && order != '|' && order != '=') {
    fail(source, descr_at, "bad byte-order mark in '" + std::string(dtype) + "'");
  }
  a.big_endian = order == '>' || (order == '=' && std::endian::native == std::endian::big);

  const auto [fortran, fortran_at] = detail_npy::dict_value(header, at, "fortran_order", source);
  if (fortran != "True" && fortran != "False") {
    fail(source, fortran_at, "fortran_order must be True or False");
  }
  a.fortran_order = fortran == "True";

  // Not a structured binding: the lambda below uses it, which clang before 16 refuses.
  const std::pair<std::string_view, std::size_t> shape_entry =
      detail_npy::dict_value(header, at, "shape", source);
  const std::string_view shape = shape_entry.first;
  const std::size_t shape_at = shape_entry.second;
  a.shape_at = shape_at;
  if (shape.size() < 2 || shape.front() != '(' || shape.back() != ')') {
    fail(source, shape_at, "shape " + std::string(shape) + " is not a tuple");
  }
  const auto too_large = [&] {
    fail(source, shape_at,
         "shape " + std::string(shape) + " exceeds the limit of " + std::to_string(max_count) +
             " values");
  };
  // Python's tuple grammar: sizes separated by commas, one trailing comma allowed ("(3,)"),
  // nothing else empty ("(100,, 1)" and "(,)" are not tuples).
  std::string_view rest = shape.substr(1, shape.size() - 2);
  for (bool more = true; more;) {
    const std::size_t comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    more = comma != std::string_view::npos;
    rest = more ? rest.substr(comma + 1) : std::string_view();
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item.empty()) {
      const bool trailing = !more && !a.shape.empty();  // "(3,)": nothing after the last comma
      const bool unit = !more && a.shape.empty();       // "()": a scalar
      if (trailing || unit) break;
      fail(source, shape_at, "shape " + std::string(shape) + " is not a tuple of sizes");
    }
    std::uint64_t d = 0;
    for (const char c : item) {
      if (c < '0' || c > '9') {
        fail(source, shape_at, "shape " + std::string(shape) + " is not a tuple of sizes");
      }
      d = d * 10 + std::uint64_t(c - '0');
      if (d > max_count) too_large();
    }
    a.shape.push_back(d);
  }
  for (const std::uint64_t d : a.shape) {
    if (d != 0 && a.count > max_count / d) too_large();
    a.count *= d;
  }
  const std::uint64_t need = a.count * std::uint64_t(a.width);
  const std::uint64_t have = bytes.size() - a.data_at;
  if (have != need) {
    const std::string sizes = "shape " + std::string(shape) + " needs " + std::to_string(need) +
                              " data bytes, the file has " + std::to_string(have);
    if (have < need) fail(source, bytes.size(), "truncated: " + sizes);
    fail(source, a.data_at + need,
         sizes + ": " + std::to_string(have - need) + " unexpected bytes after the data");
  }
  return a;
}

/// Reads a .npy file of integer readings (dtype u1, u2, u4, u8, i1, i2, i4, i8 in either byte
/// order, or f4 / f8 holding whole numbers; C or Fortran order, returned in C order) into
/// 16-bit values. Throws IoError when the file cannot be read, and IoError naming the file,
/// the byte and the problem for anything else: a bad magic or header, a shape whose size
/// disagrees with the data, or a value that is negative, fractional, not finite or above
/// 65535 (with its flat index, in C order as numpy's `flat`).
inline NpyU16 parse_npy_u16(std::string_view bytes, const std::string& source = "<npy>") {
  const NpyArray a = parse_npy_header(bytes, source, std::uint64_t{1} << 40);
  NpyU16 out;
  out.shape.assign(a.shape.begin(), a.shape.end());
  out.values.resize(a.count);
  for (std::uint64_t k = 0; k < a.count; ++k) {
    const double v = a.value(bytes, k);
    const std::uint64_t i = a.flat_index(k);
    if (!(v >= 0 && v <= 65535 && v == std::floor(v))) {
      detail_npy::fail(source, a.data_at + k * std::uint64_t(a.width),
                       "value " + std::to_string(v) + " at flat index " + std::to_string(i) +
                           " is not a reading (a whole number in [0, 65535])");
    }
    out.values[i] = static_cast<std::uint16_t>(v);
  }
  return out;
}

/// Reads a .npy file of readings (see parse_npy_u16).
inline NpyU16 read_npy_u16(const std::string& path) { return parse_npy_u16(read_file(path), path); }

/// The .npy (version 1.0, dtype '<u2') encoding of `values` with `shape`; throws
/// std::invalid_argument when the sizes disagree.
inline std::string encode_npy_u16(std::span<const std::size_t> shape,
                                  std::span<const std::uint16_t> values) {
  std::size_t count = 1;
  std::string dims;
  for (const std::size_t d : shape) {
    count *= d;
    if (!dims.empty()) dims.append(", ");
    dims.append(std::to_string(d));
  }
  if (count != values.size()) {
    throw std::invalid_argument("encode_npy_u16: shape holds " + std::to_string(count) +
                                " values, got " + std::to_string(values.size()));
  }
  // "(3, 4)" and "(5,)", as numpy writes them.
  if (shape.size() == 1) dims.push_back(',');
  std::string out = detail_npy::header_v1("<u2", "(" + dims + ")");
  for (const std::uint16_t v : values) {
    out.push_back(static_cast<char>(v & 0xFF));
    out.push_back(static_cast<char>(v >> 8));
  }
  return out;
}

namespace detail_npy {

// The shape as numpy writes it ("(3, 4)", "(5,)"), checked against `count` values.
inline std::string shape_text(std::span<const std::size_t> shape, std::size_t count,
                              const char* who) {
  std::size_t n = 1;
  std::string dims;
  for (const std::size_t d : shape) {
    n *= d;
    if (!dims.empty()) dims.append(", ");
    dims.append(std::to_string(d));
  }
  if (n != count) {
    throw std::invalid_argument(std::string(who) + ": shape holds " + std::to_string(n) +
                                " values, got " + std::to_string(count));
  }
  if (shape.size() == 1) dims.push_back(',');
  return "(" + dims + ")";
}

}  // namespace detail_npy

/// The .npy (version 1.0, dtype '<f8') encoding of `values` with `shape`; throws
/// std::invalid_argument when the sizes disagree.
inline std::string encode_npy_f64(std::span<const std::size_t> shape,
                                  std::span<const double> values) {
  std::string out =
      detail_npy::header_v1("<f8", detail_npy::shape_text(shape, values.size(), "encode_npy_f64"));
  const std::size_t at = out.size();
  out.resize(at + 8 * values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::uint64_t raw = std::bit_cast<std::uint64_t>(values[i]);
    for (std::size_t b = 0; b < 8; ++b, raw >>= 8) {
      out[at + 8 * i + b] = static_cast<char>(raw & 0xFF);
    }
  }
  return out;
}

/// The .npy (version 1.0, dtype '|u1') encoding of `values` with `shape`; throws
/// std::invalid_argument when the sizes disagree.
inline std::string encode_npy_u8(std::span<const std::size_t> shape,
                                 std::span<const std::uint8_t> values) {
  std::string out =
      detail_npy::header_v1("|u1", detail_npy::shape_text(shape, values.size(), "encode_npy_u8"));
  out.append(reinterpret_cast<const char*>(values.data()), values.size());
  return out;
}

}  // namespace taxel::io
