// SPDX-License-Identifier: MIT
// A calibration as a file (`.txcal`), binary, little-endian, in this order:
//   magic      8 bytes  "TXOCAL" 0x00 0x01 (format version 1)
//   rows, cols int32    frame size
//   pixel      float64  [m]
//   threshold  float64  contact threshold [levels]
//   method     uint8    0 polynomial, 1 lookup table
//   markers    uint8    0 or 1; then dark (float64), reach and grow (int32) of MarkerOptions
//   heldout    float64  x 2: the polynomial's and the table's held-out RMS gradient error
//   circles    uint32 count, then count x (cx, cy, radius) float64 [px]
//   background rows x cols x 3 uint8, row-major RGB (the no-contact frame)
//   polynomial uint32 features (45), then features x 2 float64, row-major (gx, gy columns)
//   table      int32 bins (0: none), float64 range, then bins^3 x 2 float32
// The background's marker dots are found again when the file is read.
//
// The same calibration as JSON (a file named *.json; encode_calibration_json): an object whose
// readable members say what the calibration is (format "taxel optical calibration", version 1,
// rows, cols, pixel_m, method, threshold, heldout_gradient_rms, heldout_polynomial,
// heldout_table, circles as [cx, cy, radius] in pixels) and whose member "txcal" holds the
// binary form above in base64 (RFC 4648). Reading takes "txcal" and checks the readable rows,
// cols and pixel_m against it, so that a hand edit of one without the other is refused.
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <string_view>

#include "taxel/core/error.hpp"
#include "taxel/io/binary.hpp"
#include "taxel/io/file.hpp"
#include "taxel/optical/calibration.hpp"

namespace taxel::optical {

namespace detail {
inline constexpr char kCalMagic[8] = {'T', 'X', 'O', 'C', 'A', 'L', 0, 1};

using io::put_le;
using CalReader = io::BinaryReader;
}  // namespace detail

/// A calibration's file bytes (see the header comment).
template <class = void>
std::string encode_calibration(const Calibration& cal) {
  std::string out(detail::kCalMagic, 8);
  detail::put_le<std::int32_t>(out, cal.rows);
  detail::put_le<std::int32_t>(out, cal.cols);
  detail::put_le<double>(out, cal.pixel);
  detail::put_le<double>(out, cal.threshold);
  detail::put_le<std::uint8_t>(out, cal.method == Calibration::Method::polynomial ? 0 : 1);
  detail::put_le<std::uint8_t>(out, cal.markers ? 1 : 0);
  detail::put_le<double>(out, cal.marker.dark);
  detail::put_le<std::int32_t>(out, cal.marker.reach);
  detail::put_le<std::int32_t>(out, cal.marker.grow);
  detail::put_le<double>(out, cal.heldout_polynomial);
  detail::put_le<double>(out, cal.heldout_table);
  detail::put_le<std::uint32_t>(out, static_cast<std::uint32_t>(cal.circles.size()));
  for (const Circle& c : cal.circles) {
    detail::put_le<double>(out, c.cx);
    detail::put_le<double>(out, c.cy);
    detail::put_le<double>(out, c.radius);
  }
  const RgbFrame bg = to_frame(cal.background);
  out.append(reinterpret_cast<const char*>(bg.data.data()), bg.data.size());
  detail::put_le<std::uint32_t>(out, static_cast<std::uint32_t>(cal.polynomial.rows()));
  for (Eigen::Index r = 0; r < cal.polynomial.rows(); ++r) {
    detail::put_le<double>(out, cal.polynomial(r, 0));
    detail::put_le<double>(out, cal.polynomial(r, 1));
  }
  detail::put_le<std::int32_t>(out, cal.table.empty() ? 0 : cal.table_bins);
  detail::put_le<double>(out, cal.table_range);
  for (const float v : cal.table) detail::put_le<float>(out, v);
  return out;
}

/// A calibration from file bytes; `source` names them in errors. Throws IoError for another
/// format or version, bytes cut short or left over, sizes out of range and values not finite.
template <class = void>
Calibration decode_calibration(std::string_view bytes,
                               const std::string& source = "<calibration>") {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), detail::kCalMagic, 6) != 0) {
    throw IoError(source, "not a taxel optical calibration (no TXOCAL header)");
  }
  if (bytes[6] != 0 || bytes[7] != 1) {
    throw IoError(source, "calibration format version " + std::to_string(int(bytes[7])) +
                              " is not supported (this taxel reads version 1)");
  }
  detail::CalReader in{bytes, source, 8};
  Calibration cal;
  cal.rows = in.get<std::int32_t>("rows");
  cal.cols = in.get<std::int32_t>("cols");
  if (cal.rows < 3 || cal.cols < 3 || cal.rows > 16384 || cal.cols > 16384) {
    throw IoError(source, "frame size " + std::to_string(cal.rows) + " x " +
                              std::to_string(cal.cols) + " out of range [3, 16384]");
  }
  cal.pixel = in.finite("pixel");
  cal.threshold = in.finite("threshold");
  if (!(cal.pixel > 0) || !(cal.threshold > 0))
    throw IoError(source, "pixel and threshold must be > 0");
  const auto method = in.get<std::uint8_t>("method");
  if (method > 1) throw IoError(source, "unknown method " + std::to_string(int(method)));
  cal.method = method == 0 ? Calibration::Method::polynomial : Calibration::Method::lookup_table;
  cal.markers = in.get<std::uint8_t>("markers") != 0;
  cal.marker.dark = in.finite("marker dark");
  cal.marker.reach = in.get<std::int32_t>("marker reach");
  cal.marker.grow = in.get<std::int32_t>("marker grow");
  cal.heldout_polynomial = in.get<double>("held-out errors");
  cal.heldout_table = in.get<double>("held-out errors");
  const auto circles = in.get<std::uint32_t>("circle count");
  if (circles > 100000) throw IoError(source, std::to_string(circles) + " circles");
  for (std::uint32_t i = 0; i < circles; ++i) {
    Circle c;
    c.cx = in.finite("circle");
    c.cy = in.finite("circle");
    c.radius = in.finite("circle");
    cal.circles.push_back(c);
  }
  const std::size_t bg_bytes = std::size_t(cal.rows) * std::size_t(cal.cols) * 3;
  if (bytes.size() - in.at < bg_bytes)
    throw IoError(source, "cut short in the background", std::nullopt, in.at);
  RgbFrame bg(cal.rows, cal.cols, 0);
  std::memcpy(bg.data.data(), bytes.data() + in.at, bg_bytes);
  in.at += bg_bytes;
  cal.background = colour_planes(bg);
  const auto features = in.get<std::uint32_t>("polynomial size");
  if (features != 0 && features != Calibration::kFeatures) {
    throw IoError(source, "the polynomial has " + std::to_string(features) + " features, not " +
                              std::to_string(Calibration::kFeatures));
  }
  cal.polynomial.resize(features, 2);
  for (std::uint32_t r = 0; r < features; ++r) {
    cal.polynomial(r, 0) = in.finite("polynomial");
    cal.polynomial(r, 1) = in.finite("polynomial");
  }
  cal.table_bins = in.get<std::int32_t>("table bins");
  cal.table_range = in.get<double>("table range");
  if (cal.table_bins != 0 && (cal.table_bins < 4 || cal.table_bins > 128 ||
                              !(cal.table_range > 0) || !std::isfinite(cal.table_range))) {
    throw IoError(source, "table of " + std::to_string(cal.table_bins) + " bins out of range");
  }
  const auto cells =
      std::size_t(cal.table_bins) * std::size_t(cal.table_bins) * std::size_t(cal.table_bins) * 2;
  cal.table.resize(cells);
  for (std::size_t i = 0; i < cells; ++i) {
    const float v = in.get<float>("table");
    if (!std::isfinite(v)) throw IoError(source, "table is not finite", std::nullopt, in.at - 4);
    cal.table[i] = v;
  }
  if (in.at != bytes.size()) {
    throw IoError(source, std::to_string(bytes.size() - in.at) + " bytes after the calibration",
                  std::nullopt, in.at);
  }
  if ((cal.method == Calibration::Method::polynomial && features == 0) ||
      (cal.method == Calibration::Method::lookup_table && cal.table_bins == 0)) {
    throw IoError(source, "the method in use has no coefficients");
  }
  if (cal.markers) {
    if (!(cal.marker.dark > 0 && cal.marker.dark < 1) || cal.marker.reach < 1 ||
        cal.marker.grow < 0) {
      throw IoError(source, "marker options out of range");
    }
    cal.background_markers = marker_mask(bg, cal.marker);
  }
  return cal;
}

namespace detail {

inline constexpr char kBase64[] =
    "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

inline std::string base64(std::string_view in) {
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (std::size_t i = 0; i < in.size(); i += 3) {
    const std::size_t n = std::min<std::size_t>(3, in.size() - i);
    std::uint32_t v = 0;
    for (std::size_t k = 0; k < 3; ++k) {
      v = v << 8 | (k < n ? static_cast<unsigned char>(in[i + k]) : 0u);
    }
    for (std::size_t k = 0; k < 4; ++k) {
      out.push_back(k <= n ? kBase64[(v >> (18 - 6 * k)) & 63] : '=');
    }
  }
  return out;
}

// Decodes base64; false on a character outside the alphabet or a length not a multiple of 4.
inline bool unbase64(std::string_view in, std::string& out) {
  if (in.size() % 4 != 0) return false;
  out.clear();
  out.reserve(in.size() / 4 * 3);
  for (std::size_t i = 0; i < in.size(); i += 4) {
    std::uint32_t v = 0;
    int pad = 0;
    for (std::size_t k = 0; k < 4; ++k) {
      const char c = in[i + k];
      int d = 0;
      if (c == '=' && i + 4 == in.size() && k >= 2) {
        ++pad;
      } else if (pad > 0) {
        return false;
      } else if (c >= 'A' && c <= 'Z') {
        d = c - 'A';
      } else if (c >= 'a' && c <= 'z') {
        d = c - 'a' + 26;
      } else if (c >= '0' && c <= '9') {
        d = c - '0' + 52;
      } else if (c == '+') {
        d = 62;
      } else if (c == '/') {
        d = 63;
      } else {
        return false;
      }
      v = v << 6 | static_cast<std::uint32_t>(d);
    }
    for (int k = 0; k < 3 - pad; ++k) out.push_back(static_cast<char>((v >> (16 - 8 * k)) & 0xFF));
  }
  return true;
}

// The text after `"key":` in a JSON object written by encode_calibration_json (blanks skipped);
// empty when the key is not there.
inline std::string_view json_member(std::string_view json, std::string_view key) {
  std::string quoted(1, '"');  // append(): GCC 12 misreports -Wrestrict on operator+ here
  quoted.append(key).push_back('"');
  std::size_t at = json.find(quoted);
  if (at == std::string_view::npos) return {};
  at = json.find_first_not_of(" \t\r\n", at + quoted.size());
  if (at == std::string_view::npos || json[at] != ':') return {};
  at = json.find_first_not_of(" \t\r\n", at + 1);
  return at == std::string_view::npos ? std::string_view{} : json.substr(at);
}

inline std::string json_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace detail

/// The JSON form of a calibration (see the header comment): readable members and the binary
/// form in base64.
template <class = void>
std::string encode_calibration_json(const Calibration& cal) {
  using detail::json_number;
  std::string out = "{\n  \"format\": \"taxel optical calibration\",\n  \"version\": 1,\n";
  out += "  \"rows\": " + std::to_string(cal.rows) + ",\n  \"cols\": " + std::to_string(cal.cols) +
         ",\n  \"pixel_m\": " + json_number(cal.pixel) + ",\n";
  out += std::string("  \"method\": \"") +
         (cal.method == Calibration::Method::polynomial ? "polynomial" : "lookup_table") +
         "\",\n  \"threshold\": " + json_number(cal.threshold) + ",\n";
  out += "  \"heldout_gradient_rms\": " + json_number(cal.heldout()) +
         ",\n  \"heldout_polynomial\": " + json_number(cal.heldout_polynomial) +
         ",\n  \"heldout_table\": " + json_number(cal.heldout_table) + ",\n  \"circles\": [";
  for (std::size_t i = 0; i < cal.circles.size(); ++i) {
    const Circle& c = cal.circles[i];
    out += (i ? ", [" : "[") + json_number(c.cx) + ", " + json_number(c.cy) + ", " +
           json_number(c.radius) + "]";
  }
  out += "],\n  \"txcal\": \"" + detail::base64(encode_calibration(cal)) + "\"\n}\n";
  return out;
}

/// A calibration from file bytes in either form: binary (TXOCAL) or JSON (a leading '{').
/// Throws IoError naming `source` and what is wrong.
template <class = void>
Calibration decode_calibration_any(std::string_view bytes,
                                   const std::string& source = "<calibration>") {
  const std::size_t first = bytes.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos || bytes[first] != '{') {
    return decode_calibration(bytes, source);
  }
  const std::string_view format = detail::json_member(bytes, "format");
  if (!format.starts_with("\"taxel optical calibration\"")) {
    throw IoError(source,
                  "a JSON file but not a taxel optical calibration (no \"format\": "
                  "\"taxel optical calibration\")");
  }
  const std::string_view data = detail::json_member(bytes, "txcal");
  const std::size_t end = data.empty() ? std::string_view::npos : data.find('"', 1);
  if (data.empty() || data[0] != '"' || end == std::string_view::npos) {
    throw IoError(source, "the calibration's \"txcal\" string is missing");
  }
  std::string binary;
  if (!detail::unbase64(data.substr(1, end - 1), binary)) {
    throw IoError(source, "the calibration's \"txcal\" string is not base64");
  }
  Calibration cal = decode_calibration(binary, source + " (txcal)");
  // The readable members must say what the binary form does.
  const auto number = [&](std::string_view key) {
    const std::string_view v = detail::json_member(bytes, key);
    char* stop = nullptr;
    const std::string text(v.substr(0, std::min<std::size_t>(v.size(), 40)));
    const double x = std::strtod(text.c_str(), &stop);
    if (v.empty() || stop == text.c_str()) {
      throw IoError(source, "the calibration's \"" + std::string(key) + "\" is not a number");
    }
    return x;
  };
  if (number("rows") != cal.rows || number("cols") != cal.cols ||
      !(std::abs(number("pixel_m") - cal.pixel) <= 1e-12 * cal.pixel)) {
    throw IoError(source, "rows, cols or pixel_m disagree with the calibration in \"txcal\"");
  }
  return cal;
}

/// Writes a calibration file (atomically: a failed write keeps the old file): JSON when
/// `path` ends in .json, the binary form otherwise. Throws IoError.
template <class = void>
void save_calibration(const std::string& path, const Calibration& cal) {
  const bool json = path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
  io::write_file(path, json ? encode_calibration_json(cal) : encode_calibration(cal));
}

/// Reads a calibration file in either form. Throws IoError naming the file and what is wrong.
template <class = void>
Calibration load_calibration(const std::string& path) {
  return decode_calibration_any(io::read_file(path), path);
}

}  // namespace taxel::optical
