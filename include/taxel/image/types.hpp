// SPDX-License-Identifier: MIT
// Image types of taxel::image: Eigen row-major arrays, views over them, and small enums.
#pragma once

#include <Eigen/Core>
#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>

namespace taxel::image {

/// A 2-D image: `rows x cols`, row-major, indexed `(row, col)`, 0-based.
template <class T>
using Image = Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Pressure image (any units; the second paper's images are 8-bit levels in [0, 255]).
using ImageD = Image<double>;
/// Binary mask: 0 = outside, anything else = inside.
using Mask = Image<std::uint8_t>;
/// Label image: 0 = background, 1..n = component number.
using Labels = Image<std::int32_t>;

/// Read-only view of a pressure image; accepts `ImageD`, blocks of it and `Eigen::Map`s.
using ImageView = Eigen::Ref<const ImageD>;
/// Read-only view of a mask.
using MaskView = Eigen::Ref<const Mask>;

/// Pixel adjacency for connected components.
enum class Connectivity : int {
  four = 4,   ///< edge neighbours only
  eight = 8,  ///< edge and corner neighbours (MATLAB's default for 2-D)
};

/// Which end of the intensity scale means pressure. The second paper's text (its segmentation
/// keeps the "lowest centroid" class) and its figure captions (dark = no contact) disagree;
/// taxel defaults to the physically meaningful reading.
enum class Polarity {
  high_is_pressure,  ///< larger values = more pressure (sensor counts, the figure captions)
  dark_is_pressure,  ///< smaller values = more pressure (the text's "lowest centroid" wording)
};

/// Lower-case name of a polarity, as spelled in the enum.
constexpr std::string_view to_string(Polarity p) noexcept {
  return p == Polarity::high_is_pressure ? "high_is_pressure" : "dark_is_pressure";
}

/// Largest image the preallocating image types (Segmenter, RegionAnalyzer, Reconstructor,
/// Recognizer) accept: 2^24 pixels (4096 x 4096).
inline constexpr Eigen::Index kMaxImagePixels = Eigen::Index{1} << 24;

namespace detail {

/// `rows * cols` when both are >= 0 and the product is at most kMaxImagePixels; otherwise
/// throws std::invalid_argument naming `who` (a negative size never reaches an allocation).
template <class = void>
inline Eigen::Index checked_pixels(const char* who, Eigen::Index rows, Eigen::Index cols) {
  if (rows < 0 || cols < 0 || (cols > 0 && rows > kMaxImagePixels / cols)) {
    throw std::invalid_argument(std::string(who) + ": an image of " + std::to_string(rows) + " x " +
                                std::to_string(cols) +
                                " pixels; rows and cols must be >= 0 with at most " +
                                std::to_string(kMaxImagePixels) + " pixels");
  }
  return rows * cols;
}

/// The non-zero pixels of a mask row of at most 64 pixels as bits (bit c = pixel c).
template <class = void>
inline std::uint64_t pack_row(const std::uint8_t* m, Eigen::Index cols) noexcept {
  std::uint64_t bits = 0;
  Eigen::Index c = 0;
  if constexpr (std::endian::native == std::endian::little) {
    constexpr std::uint64_t kLow7 = 0x7F7F7F7F7F7F7F7FULL;
    constexpr std::uint64_t kHigh = 0x8080808080808080ULL;
    for (; c + 8 <= cols; c += 8) {
      std::uint64_t x = 0;
      std::memcpy(&x, m + c, 8);
      // Bit 7 of every non-zero byte, then byte k's bit moved to bit k by one multiply.
      const std::uint64_t nonzero = (((x & kLow7) + kLow7) | x) & kHigh;
      bits |= (((nonzero >> 7) * 0x0102040810204080ULL) >> 56) << c;
    }
  }
  for (; c < cols; ++c) bits |= std::uint64_t{m[c] != 0 ? 1u : 0u} << c;
  return bits;
}

}  // namespace detail

}  // namespace taxel::image
