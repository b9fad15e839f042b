// SPDX-License-Identifier: MIT
// Frames of camera-based tactile sensors (GelSight and DIGIT class): 8-bit RGB frames and their
// colour planes.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/image/types.hpp"
#include "taxel/io/picture.hpp"

namespace taxel::optical {

/// A plane of doubles, rows x cols, row-major, indexed (row, col).
using Plane = image::Image<double>;

/// An 8-bit RGB frame: rows x cols pixels, row-major, channels interleaved (R, G, B). The
/// pictures of `io/picture.hpp` (`io::read_png` reads them from files).
using RgbFrame = io::RgbImage;

/// Throws std::invalid_argument unless a frame has at least 3 x 3 pixels and rows * cols * 3
/// bytes.
inline void validate_frame(const RgbFrame& f, const char* who) {
  image::detail::checked_pixels(who, f.rows, f.cols);
  if (f.rows < 3 || f.cols < 3 ||
      f.data.size() != static_cast<std::size_t>(f.rows) * static_cast<std::size_t>(f.cols) * 3) {
    throw std::invalid_argument(std::string(who) + ": a frame of " + std::to_string(f.rows) +
                                " x " + std::to_string(f.cols) +
                                " pixels needs rows, cols >= 3 and rows * cols * 3 bytes; it "
                                "has " +
                                std::to_string(f.data.size()));
  }
}

/// The three colour planes of a frame, as doubles in [0, 255].
using Colour = std::array<Plane, 3>;

/// A frame's colour planes.
template <class = void>
Colour colour_planes(const RgbFrame& f) {
  validate_frame(f, "colour_planes");
  Colour out;
  for (Plane& p : out) p.resize(f.rows, f.cols);
  for (int r = 0; r < f.rows; ++r) {
    for (int c = 0; c < f.cols; ++c) {
      const std::uint8_t* px =
          f.data.data() + (static_cast<std::size_t>(r) * static_cast<std::size_t>(f.cols) +
                           static_cast<std::size_t>(c)) *
                              3;
      for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(k)](r, c) = px[k];
    }
  }
  return out;
}

/// Rounds colour planes to an 8-bit frame (clipped to [0, 255]).
template <class = void>
RgbFrame to_frame(const Colour& planes) {
  RgbFrame f(planes[0].rows(), planes[0].cols(), 0);
  std::size_t i = 0;
  for (int r = 0; r < f.rows; ++r) {
    for (int c = 0; c < f.cols; ++c) {
      for (int k = 0; k < 3; ++k) {
        const double v = planes[static_cast<std::size_t>(k)](r, c);
        f.data[i++] = static_cast<std::uint8_t>(v <= 0 ? 0 : v >= 255 ? 255 : v + 0.5);
      }
    }
  }
  return f;
}

/// A no-contact background estimated from frames that mostly show the gel untouched: per pixel
/// and channel, the median of the frames (the upper one of an even count). A touch that covers
/// a pixel in fewer than half of the frames leaves no trace. Throws std::invalid_argument for
/// no frames or frames of different sizes.
template <class = void>
RgbFrame median_background(const std::vector<RgbFrame>& frames) {
  if (frames.empty()) throw std::invalid_argument("median_background: no frames");
  for (std::size_t i = 0; i < frames.size(); ++i) {
    validate_frame(frames[i], "median_background");
    if (frames[i].rows != frames[0].rows || frames[i].cols != frames[0].cols) {
      throw std::invalid_argument(
          "median_background: frame " + std::to_string(i) + " is " +
          std::to_string(frames[i].rows) + " x " + std::to_string(frames[i].cols) + ", frame 0 " +
          std::to_string(frames[0].rows) + " x " + std::to_string(frames[0].cols));
    }
  }
  RgbFrame out(frames[0].rows, frames[0].cols, 0);
  std::vector<std::uint8_t> v(frames.size());
  for (std::size_t i = 0; i < out.data.size(); ++i) {
    for (std::size_t f = 0; f < frames.size(); ++f) v[f] = frames[f].data[i];
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    out.data[i] = v[v.size() / 2];
  }
  return out;
}

}  // namespace taxel::optical
