// SPDX-License-Identifier: MIT
// NumPy .npy arrays of integer readings: a stack of tactile frames as numpy saves it
// (np.save("readings.npy", frames), frames of shape (frames, rows, cols) or
// (frames, pads, rows, cols)). Format: NEP 1, "A simple file format for NumPy arrays",
// versions 1.0, 2.0 and 3.0.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/io/file.hpp"

namespace taxel::io {

/// An n-dimensional array of unsigned 16-bit values in C (row-major) order.
struct NpyU16 {
  std::vector<std::size_t> shape;     ///< dimensions, outermost first
  std::vector<std::uint16_t> values;  ///< product(shape) values
};

namespace detail_npy {

[[noreturn]] inline void fail(const std::string& source, const std::string& why) {
  throw IoError(source, why);
}

// The value of `key` in the header dict, up to the next top-level ',' or '}' (a tuple kept
// whole).
inline std::string_view dict_value(std::string_view header, std::string_view key,
                                   const std::string& source) {
  std::size_t at = std::string_view::npos;
  for (const char q : {'\'', '"'}) {
    const std::string quoted = std::string(1, q) + std::string(key) + q;
    at = header.find(quoted);
    if (at != std::string_view::npos) {
      at += quoted.size();
      break;
    }
  }
  if (at == std::string_view::npos) fail(source, "header has no '" + std::string(key) + "'");
  at = header.find(':', at);
  if (at == std::string_view::npos) fail(source, "header: no ':' after '" + std::string(key) + "'");
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
  if (end >= header.size())
    fail(source, "header: unterminated value of '" + std::string(key) + "'");
  std::string_view v = header.substr(at, end - at);
  while (!v.empty() && v.back() == ' ') v.remove_suffix(1);
  return v;
}

}  // namespace detail_npy

/// Reads a .npy file of integer readings (dtype u1, u2, u4, u8, i1, i2, i4, i8 in either byte
/// order, or f4 / f8 holding whole numbers) into 16-bit values. Throws IoError when the file
/// cannot be read, and IoError naming the file and the problem for anything else: a bad
/// magic or header, Fortran order, a shape whose size disagrees with the data, or a value that
/// is negative, fractional, not finite or above 65535 (with its flat index).
inline NpyU16 parse_npy_u16(std::string_view bytes, const std::string& source = "<npy>") {
  using detail_npy::fail;
  if (bytes.size() < 10 || bytes.substr(0, 6) != std::string_view("\x93NUMPY", 6)) {
    fail(source, "not a .npy file (no \\x93NUMPY magic)");
  }
  const auto major = static_cast<unsigned char>(bytes[6]);
  std::size_t header_len = 0, offset = 0;
  if (major == 1) {
    header_len = static_cast<unsigned char>(bytes[8]) |
                 (std::size_t(static_cast<unsigned char>(bytes[9])) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) fail(source, "truncated header");
    header_len = 0;
    for (int k = 0; k < 4; ++k) {
      header_len |= std::size_t(static_cast<unsigned char>(bytes[8 + k])) << (8 * k);
    }
    offset = 12;
  } else {
    fail(source, "unsupported .npy version " + std::to_string(major));
  }
  if (header_len > bytes.size() - offset) fail(source, "truncated header");
  const std::string_view header = bytes.substr(offset, header_len);
  offset += header_len;

  const std::string_view descr = detail_npy::dict_value(header, "descr", source);
  if (descr.size() < 5 || (descr.front() != '\'' && descr.front() != '"') ||
      descr.back() != descr.front()) {
    fail(source, "descr " + std::string(descr) + " is not a simple dtype string");
  }
  const std::string_view dtype = descr.substr(1, descr.size() - 2);  // e.g. <u2
  const char order = dtype[0];
  const char kind = dtype[1];
  int width = 0;
  if (dtype.size() == 3 && dtype[2] >= '1' && dtype[2] <= '8') width = dtype[2] - '0';
  const bool int_ok =
      (kind == 'u' || kind == 'i') && (width == 1 || width == 2 || width == 4 || width == 8);
  const bool float_ok = kind == 'f' && (width == 4 || width == 8);
  if ((order != '<' && order != '>' && order != '|' && order != '=') || !(int_ok || float_ok)) {
    fail(source, "dtype '" + std::string(dtype) +
                     "' is not supported; integer readings need u1/u2/u4/u8/i1/i2/i4/i8 or f4/f8");
  }
  const bool big = order == '>' || (order == '=' && std::endian::native == std::endian::big);
  if (detail_npy::dict_value(header, "fortran_order", source) != "False") {
    fail(source, "Fortran-ordered arrays are not supported; save with np.ascontiguousarray");
  }
  const std::string_view shape_text = detail_npy::dict_value(header, "shape", source);
  if (shape_text.size() < 2 || shape_text.front() != '(' || shape_text.back() != ')') {
    fail(source, "shape " + std::string(shape_text) + " is not a tuple");
  }
  NpyU16 out;
  std::size_t count = 1;
  std::string_view rest = shape_text.substr(1, shape_text.size() - 2);
  while (!rest.empty()) {
    const std::size_t comma = rest.find(',');
    std::string_view item = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item.empty()) continue;
    std::size_t d = 0;
    for (const char c : item) {
      if (c < '0' || c > '9' || d > (std::numeric_limits<std::uint32_t>::max() / 10)) {
        fail(source, "shape " + std::string(shape_text) + " is not a tuple of sizes");
      }
      d = d * 10 + std::size_t(c - '0');
    }
    out.shape.push_back(d);
    if (d != 0 && count > (std::size_t{1} << 40) / d) fail(source, "shape too large");
    count *= d;
  }
  const std::size_t need = count * std::size_t(width);
  if (bytes.size() - offset != need) {
    fail(source, "shape " + std::string(shape_text) + " needs " + std::to_string(need) +
                     " data bytes, the file has " + std::to_string(bytes.size() - offset));
  }
  out.values.resize(count);
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data() + offset);
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t raw = 0;
    for (int k = 0; k < width; ++k) {
      const std::uint64_t byte = data[i * std::size_t(width) + std::size_t(k)];
      raw |= byte << (8 * (big ? width - 1 - k : k));
    }
    double v = 0.0;
    bool ok = true;
    if (kind == 'u') {
      ok = raw <= 65535;
      v = double(raw);
    } else if (kind == 'i') {
      const int shift = 64 - 8 * width;
      const auto s = static_cast<std::int64_t>(raw << shift) >> shift;  // sign-extend
      ok = s >= 0 && s <= 65535;
      v = double(s);
    } else if (width == 4) {
      v = double(std::bit_cast<float>(static_cast<std::uint32_t>(raw)));
      ok = v >= 0 && v <= 65535 && v == std::floor(v);
    } else {
      v = std::bit_cast<double>(raw);
      ok = v >= 0 && v <= 65535 && v == std::floor(v);
    }
    if (!ok) {
      fail(source, "value " + std::to_string(v) + " at flat index " + std::to_string(i) +
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
  std::string header;  // append(): GCC 12 misreports -Wstringop-overflow on operator+ here
  header.append("{'descr': '<u2', 'fortran_order': False, 'shape': (").append(dims).append("), }");
  // Pad with spaces and a newline so that the data start at a multiple of 64 bytes.
  const std::size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(header.size() & 0xFF));
  out.push_back(static_cast<char>(header.size() >> 8));
  out += header;
  for (const std::uint16_t v : values) {
    out.push_back(static_cast<char>(v & 0xFF));
    out.push_back(static_cast<char>(v >> 8));
  }
  return out;
}

}  // namespace taxel::io
