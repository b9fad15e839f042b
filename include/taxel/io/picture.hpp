// SPDX-License-Identifier: MIT
// Pictures for humans: 8-bit RGB images made from pressure images, label images and height
// maps, with a colour map, upscaling and side-by-side panels. Encoded by io/png.hpp or as PPM.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/image/types.hpp"

namespace taxel::io {

/// An 8-bit RGB picture, row-major, 3 bytes per pixel.
struct RgbImage {
  Eigen::Index rows = 0;           ///< Height [px].
  Eigen::Index cols = 0;           ///< Width [px].
  std::vector<std::uint8_t> data;  ///< rows * cols * 3 bytes

  RgbImage() = default;
  /// A picture of r x c pixels, each of grey level `fill`.
  RgbImage(Eigen::Index r, Eigen::Index c, std::uint8_t fill = 255)
      : rows(r), cols(c), data(static_cast<std::size_t>(r * c * 3), fill) {}
  /// Pointer to the 3 bytes of pixel (r, c).
  std::uint8_t* at(Eigen::Index r, Eigen::Index c) {
    return data.data() + static_cast<std::size_t>((r * cols + c) * 3);
  }
  /// Pointer to the 3 bytes of pixel (r, c).
  [[nodiscard]] const std::uint8_t* at(Eigen::Index r, Eigen::Index c) const {
    return data.data() + static_cast<std::size_t>((r * cols + c) * 3);
  }
};

/// A perceptually ordered colour ramp (dark blue - teal - yellow, close to viridis) at t in
/// [0, 1], by linear interpolation between 6 anchors.
inline std::array<std::uint8_t, 3> ramp(double t) {
  static constexpr double kAnchors[6][3] = {{68, 1, 84},    {65, 68, 135},  {42, 120, 142},
                                            {34, 168, 132}, {122, 209, 81}, {253, 231, 37}};
  t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 5.0;
  const int i = std::min(4, static_cast<int>(t));
  const double f = t - i;
  std::array<std::uint8_t, 3> rgb{};
  for (int k = 0; k < 3; ++k) {
    rgb[static_cast<std::size_t>(k)] =
        static_cast<std::uint8_t>(std::lround(kAnchors[i][k] * (1 - f) + kAnchors[i + 1][k] * f));
  }
  return rgb;
}

/// Colours `img` with `ramp`, mapping [lo, hi] to [0, 1]; each pixel becomes `scale x scale`.
/// lo == hi maps everything to the ramp's start.
template <class = void>
inline RgbImage colorize(const image::ImageView& img, double lo, double hi, int scale = 8) {
  if (scale < 1) throw std::invalid_argument("colorize: scale must be >= 1");
  RgbImage out(img.rows() * scale, img.cols() * scale);
  for (Eigen::Index r = 0; r < out.rows; ++r) {
    for (Eigen::Index c = 0; c < out.cols; ++c) {
      const double v = img(r / scale, c / scale);
      const auto rgb = ramp(hi > lo ? (v - lo) / (hi - lo) : 0.0);
      std::copy(rgb.begin(), rgb.end(), out.at(r, c));
    }
  }
  return out;
}

/// Colours small integer classes (0 = black, then distinct colours), `scale x scale` each.
template <class = void>
inline RgbImage colorize_classes(const Eigen::Ref<const image::Image<std::uint8_t>>& classes,
                                 int scale = 8) {
  static constexpr std::uint8_t kPalette[8][3] = {{0, 0, 0},       {110, 110, 110}, {255, 255, 255},
                                                  {230, 85, 13},   {49, 130, 189},  {49, 163, 84},
                                                  {117, 107, 177}, {222, 45, 38}};
  if (scale < 1) throw std::invalid_argument("colorize_classes: scale must be >= 1");
  RgbImage out(classes.rows() * scale, classes.cols() * scale);
  for (Eigen::Index r = 0; r < out.rows; ++r) {
    for (Eigen::Index c = 0; c < out.cols; ++c) {
      const auto* p = kPalette[classes(r / scale, c / scale) % 8];
      std::copy(p, p + 3, out.at(r, c));
    }
  }
  return out;
}

/// Places pictures side by side with `gap` white pixels between them (top-aligned).
template <class = void>
inline RgbImage side_by_side(const std::vector<RgbImage>& panels, Eigen::Index gap = 8) {
  Eigen::Index rows = 0, cols = 0;
  for (const auto& p : panels) {
    rows = std::max(rows, p.rows);
    cols += p.cols;
  }
  if (!panels.empty()) cols += gap * static_cast<Eigen::Index>(panels.size() - 1);
  RgbImage out(rows, cols);
  Eigen::Index x0 = 0;
  for (const auto& p : panels) {
    for (Eigen::Index r = 0; r < p.rows; ++r) {
      std::copy(p.at(r, 0), p.at(r, 0) + p.cols * 3, out.at(r, x0));
    }
    x0 += p.cols + gap;
  }
  return out;
}

/// Places pictures one above the other with `gap` white pixels between them (left-aligned).
template <class = void>
inline RgbImage stacked(const std::vector<RgbImage>& panels, Eigen::Index gap = 8) {
  Eigen::Index rows = 0, cols = 0;
  for (const auto& p : panels) {
    cols = std::max(cols, p.cols);
    rows += p.rows;
  }
  if (!panels.empty()) rows += gap * static_cast<Eigen::Index>(panels.size() - 1);
  RgbImage out(rows, cols);
  Eigen::Index y0 = 0;
  for (const auto& p : panels) {
    for (Eigen::Index r = 0; r < p.rows; ++r) {
      std::copy(p.at(r, 0), p.at(r, 0) + p.cols * 3, out.at(y0 + r, 0));
    }
    y0 += p.rows + gap;
  }
  return out;
}

/// Encodes a picture as binary PPM (P6), readable by every image viewer; no dependency.
inline std::string encode_ppm(const RgbImage& img) {
  std::string out = "P6\n" + std::to_string(img.cols) + " " + std::to_string(img.rows) + "\n255\n";
  out.append(reinterpret_cast<const char*>(img.data.data()), img.data.size());
  return out;
}

}  // namespace taxel::io
