// SPDX-License-Identifier: MIT
// Frames of camera-based tactile sensors (GelSight and DIGIT class): 8-bit RGB frames, colour
// planes, and the colour change against a no-contact background.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/image/types.hpp"

namespace taxel::optical {

/// A plane of doubles, rows x cols, row-major, indexed (row, col).
using Plane = image::Image<double>;

/// An 8-bit RGB frame: rows x cols pixels, row-major, channels interleaved (R, G, B).
struct RgbFrame {
  int rows = 0;                    ///< pixel rows
  int cols = 0;                    ///< pixel columns
  std::vector<std::uint8_t> data;  ///< rows * cols * 3 bytes

  /// A black frame of the given size. Throws std::invalid_argument for a size out of range.
  static RgbFrame zeros(int rows, int cols) {
    image::detail::checked_pixels("RgbFrame", rows, cols);
    if (rows < 3 || cols < 3) throw std::invalid_argument("RgbFrame: at least 3 x 3 pixels");
    RgbFrame f;
    f.rows = rows;
    f.cols = cols;
    f.data.assign(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols) * 3, 0);
    return f;
  }
  /// Channel k (0 R, 1 G, 2 B) of pixel (r, c).
  std::uint8_t at(int r, int c, int k) const {
    return data[(static_cast<std::size_t>(r) * static_cast<std::size_t>(cols) +
                 static_cast<std::size_t>(c)) *
                    3 +
                static_cast<std::size_t>(k)];
  }
  /// Throws std::invalid_argument unless the size and the buffer agree.
  void validate(const char* who) const {
    if (rows < 3 || cols < 3 ||
        data.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols) * 3) {
      throw std::invalid_argument(std::string(who) + ": a frame of " + std::to_string(rows) +
                                  " x " + std::to_string(cols) +
                                  " pixels needs rows, cols >= 3 "
                                  "and rows * cols * 3 bytes; it has " +
                                  std::to_string(data.size()));
    }
  }
};

/// The three colour planes of a frame, as doubles in [0, 255].
using Colour = std::array<Plane, 3>;

/// A frame's colour planes.
template <class = void>
Colour colour_planes(const RgbFrame& f) {
  f.validate("colour_planes");
  Colour out;
  for (Plane& p : out) p.resize(f.rows, f.cols);
  for (int r = 0; r < f.rows; ++r) {
    for (int c = 0; c < f.cols; ++c) {
      for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(k)](r, c) = f.at(r, c, k);
    }
  }
  return out;
}

/// Rounds colour planes to an 8-bit frame (clipped to [0, 255]).
template <class = void>
RgbFrame to_frame(const Colour& planes) {
  RgbFrame f =
      RgbFrame::zeros(static_cast<int>(planes[0].rows()), static_cast<int>(planes[0].cols()));
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

}  // namespace taxel::optical
