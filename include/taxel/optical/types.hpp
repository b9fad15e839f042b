// SPDX-License-Identifier: MIT
// Frames of camera-based tactile sensors (GelSight and DIGIT class): 8-bit RGB frames and their
// colour planes.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/image/types.hpp"
#include "taxel/io/npy.hpp"
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

/// Frames from a .npy array of 8-bit RGB, as numpy holds camera frames: shape (rows, cols, 3)
/// for one frame or (frames, rows, cols, 3) for a stack, dtype uint8. Throws IoError naming
/// `source` for another dtype or shape.
template <class = void>
std::vector<RgbFrame> decode_npy_frames(std::string_view bytes,
                                        const std::string& source = "<npy>") {
  const io::NpyArray a = io::parse_npy_header(bytes, source, std::uint64_t{1} << 32);
  if (a.kind != 'u' || a.width != 1) {
    throw IoError(source, "frames must be uint8 (RGB, 0-255)");
  }
  const std::size_t d = a.shape.size();
  if ((d != 3 && d != 4) || a.shape[d - 1] != 3) {
    throw IoError(source, "frames must have shape (rows, cols, 3) or (frames, rows, cols, 3)");
  }
  const std::uint64_t frames = d == 4 ? a.shape[0] : 1, rows = a.shape[d - 3],
                      cols = a.shape[d - 2];
  if (frames == 0 || rows < 3 || cols < 3 || rows > 16384 || cols > 16384) {
    throw IoError(source, "no frames, or a frame size out of [3, 16384]");
  }
  std::vector<RgbFrame> out;
  const std::uint64_t per = rows * cols * 3;
  for (std::uint64_t f = 0; f < frames; ++f) {
    out.emplace_back(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols), 0);
    if (!a.fortran_order)
      std::memcpy(out.back().data.data(), bytes.data() + a.data_at + f * per, per);
  }
  if (a.fortran_order) {  // the values in file order, each to its row-major place
    for (std::uint64_t k = 0; k < a.count; ++k) {
      const std::uint64_t i = a.flat_index(k);
      out[i / per].data[i % per] = static_cast<std::uint8_t>(bytes[a.data_at + k]);
    }
  }
  return out;
}

}  // namespace taxel::optical
