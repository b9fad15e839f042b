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
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

#include "taxel/core/error.hpp"
#include "taxel/io/file.hpp"
#include "taxel/optical/calibration.hpp"

namespace taxel::optical {

namespace detail {
inline constexpr char kCalMagic[8] = {'T', 'X', 'O', 'C', 'A', 'L', 0, 1};

template <class T>
void put(std::string& out, T v) {
  static_assert(std::endian::native == std::endian::little, "little-endian hosts only");
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out.append(b, sizeof(T));
}

struct CalReader {
  std::string_view bytes;
  std::string source;
  std::size_t at = 0;
  template <class T>
  T get(const char* what) {
    if (bytes.size() - at < sizeof(T)) {
      throw IoError(source, std::string("cut short in ") + what, std::nullopt, at);
    }
    T v;
    std::memcpy(&v, bytes.data() + at, sizeof(T));
    at += sizeof(T);
    return v;
  }
  double finite(const char* what) {
    const double v = get<double>(what);
    if (!std::isfinite(v))
      throw IoError(source, std::string(what) + " is not finite", std::nullopt, at - 8);
    return v;
  }
};
}  // namespace detail

/// A calibration's file bytes (see the header comment).
template <class = void>
std::string encode_calibration(const Calibration& cal) {
  std::string out(detail::kCalMagic, 8);
  detail::put<std::int32_t>(out, cal.rows);
  detail::put<std::int32_t>(out, cal.cols);
  detail::put<double>(out, cal.pixel);
  detail::put<double>(out, cal.threshold);
  detail::put<std::uint8_t>(out, cal.method == Calibration::Method::polynomial ? 0 : 1);
  detail::put<std::uint8_t>(out, cal.markers ? 1 : 0);
  detail::put<double>(out, cal.marker.dark);
  detail::put<std::int32_t>(out, cal.marker.reach);
  detail::put<std::int32_t>(out, cal.marker.grow);
  detail::put<double>(out, cal.heldout_polynomial);
  detail::put<double>(out, cal.heldout_table);
  detail::put<std::uint32_t>(out, static_cast<std::uint32_t>(cal.circles.size()));
  for (const Circle& c : cal.circles) {
    detail::put<double>(out, c.cx);
    detail::put<double>(out, c.cy);
    detail::put<double>(out, c.radius);
  }
  const RgbFrame bg = to_frame(cal.background);
  out.append(reinterpret_cast<const char*>(bg.data.data()), bg.data.size());
  detail::put<std::uint32_t>(out, static_cast<std::uint32_t>(cal.polynomial.rows()));
  for (Eigen::Index r = 0; r < cal.polynomial.rows(); ++r) {
    detail::put<double>(out, cal.polynomial(r, 0));
    detail::put<double>(out, cal.polynomial(r, 1));
  }
  detail::put<std::int32_t>(out, cal.table.empty() ? 0 : cal.table_bins);
  detail::put<double>(out, cal.table_range);
  for (const float v : cal.table) detail::put<float>(out, v);
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

/// Writes a calibration file (atomically: a failed write keeps the old file). Throws IoError.
template <class = void>
void save_calibration(const std::string& path, const Calibration& cal) {
  io::write_file(path, encode_calibration(cal));
}

/// Reads a calibration file. Throws IoError naming the file and what is wrong.
template <class = void>
Calibration load_calibration(const std::string& path) {
  return decode_calibration(io::read_file(path), path);
}

}  // namespace taxel::optical
