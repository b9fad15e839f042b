// SPDX-License-Identifier: MIT
// Pressure images from CSV, PGM (P2/P5, 8 or 16 bit) and NPY (2-D image or 3-D stack of frames,
// integers and floats), read strictly: every error says where (line and column,
// or byte offset) and what was expected. Writers for PGM and NPY; PNG is in io/png.hpp.
//
// CSV layout: one image row per line, values separated by commas (spaces and tabs around them
// are allowed), every row the same length; blank lines and lines starting with '#' are skipped.
#pragma once

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/image/types.hpp"
#include "taxel/io/file.hpp"
#include "taxel/io/npy.hpp"

namespace taxel::io {

/// Largest image the readers accept, in pixels over all frames: 2^24 = 16 Mi values (128 MiB
/// as doubles; 16 000 frames of 32 x 32). Larger files are refused before any allocation.
inline constexpr std::uint64_t kMaxImageValues = std::uint64_t{1} << 24;

/// One image or a stack of equally sized frames, row-major, frame after frame.
struct ImageStack {
  Eigen::Index frames = 0;     ///< number of frames (1 for a single image)
  Eigen::Index rows = 0;       ///< rows of each frame
  Eigen::Index cols = 0;       ///< columns of each frame
  std::vector<double> values;  ///< frames * rows * cols values

  /// A read-only view of frame `i` (0-based).
  [[nodiscard]] Eigen::Map<const image::ImageD> frame(Eigen::Index i) const {
    return {values.data() + i * rows * cols, rows, cols};
  }
};

namespace detail {

[[noreturn]] inline void fail_at_byte(const std::string& source, std::size_t offset,
                                      const std::string& why) {
  throw IoError(source, why, std::nullopt, offset);
}

inline void check_size(const std::string& source, std::uint64_t frames, std::uint64_t rows,
                       std::uint64_t cols, std::size_t offset) {
  if (rows == 0 || cols == 0 || frames == 0) fail_at_byte(source, offset, "image has no pixels");
  if (rows > kMaxImageValues || cols > kMaxImageValues || frames > kMaxImageValues ||
      rows * cols > kMaxImageValues / frames) {
    fail_at_byte(source, offset,
                 "image of " + std::to_string(frames) + " x " + std::to_string(rows) + " x " +
                     std::to_string(cols) + " values exceeds the limit of " +
                     std::to_string(kMaxImageValues));
  }
}

}  // namespace detail

/// Parses a CSV image. Throws IoError naming the line (and column) of the first error.
template <class = void>
inline ImageStack parse_image_csv(std::string_view text, const std::string& source = "<csv>") {
  ImageStack out;
  out.frames = 1;
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const std::uint64_t line_no = lines.line_number();
    if (blank_or_comment(line)) continue;
    // Values are separated by commas or, on a line without commas, by whitespace (numpy's
    // np.savetxt default).
    const bool commas = line.find(',') != std::string_view::npos;
    Eigen::Index cols = 0;
    std::size_t i = 0;
    while (true) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ',' && line[i] != ' ' && line[i] != '\t') ++i;
      const std::string_view field = line.substr(start, i - start);
      const std::string where = "column " + std::to_string(cols + 1) + " (pixel row " +
                                std::to_string(out.rows) + ", column " + std::to_string(cols) +
                                "): ";
      if (field.empty()) throw IoError(source, where + "empty value", line_no);
      double v = 0;
      const char* b = field.data();
      const char* e = b + field.size();
      if (*b == '+') ++b;
      const auto res = std::from_chars(b, e, v);
      if (res.ec != std::errc() || res.ptr != e) {
        throw IoError(source, where + "'" + std::string(field) + "' is not a number", line_no);
      }
      if (!std::isfinite(v)) {
        throw IoError(source, where + "value '" + std::string(field) + "' is not finite", line_no);
      }
      if (out.values.size() >= kMaxImageValues) {
        throw IoError(source, "more than " + std::to_string(kMaxImageValues) + " values", line_no);
      }
      out.values.push_back(v);
      ++cols;
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i == line.size()) break;
      if (!commas) continue;
      if (line[i] != ',') {
        throw IoError(source, where + "expected ',' between values", line_no);
      }
      ++i;
    }
    if (out.rows == 0) {
      out.cols = cols;
    } else if (cols != out.cols) {
      throw IoError(source,
                    "row has " + std::to_string(cols) + " values; the first row has " +
                        std::to_string(out.cols),
                    line_no);
    }
    ++out.rows;
  }
  if (out.rows == 0) throw IoError(source, "no image rows (empty file)");
  return out;
}

/// Parses a PGM image (P2 ASCII or P5 binary, maxval 1..65535, 16-bit samples big-endian as
/// Netpbm specifies). Several images of the same size, one after another, make a stack.
/// Throws IoError with the byte offset of the first error.
template <class = void>
inline ImageStack parse_pgm(std::string_view bytes, const std::string& source = "<pgm>") {
  ImageStack out;
  std::size_t pos = 0;
  auto skip_space = [&] {
    while (pos < bytes.size()) {
      const char ch = bytes[pos];
      if (ch == '#') {
        while (pos < bytes.size() && bytes[pos] != '\n') ++pos;
      } else if (ch == ' ' || ch == '\t' || ch == '\n' || ch == '\r' || ch == '\v' || ch == '\f') {
        ++pos;
      } else {
        break;
      }
    }
  };
  auto number = [&](const char* what, std::uint64_t max) -> std::uint64_t {
    skip_space();
    const std::size_t start = pos;
    std::uint64_t v = 0;
    while (pos < bytes.size() && bytes[pos] >= '0' && bytes[pos] <= '9') {
      v = v * 10 + static_cast<std::uint64_t>(bytes[pos] - '0');
      if (v > max) {
        detail::fail_at_byte(source, start, std::string(what) + " exceeds " + std::to_string(max));
      }
      ++pos;
    }
    if (pos == start) {
      detail::fail_at_byte(source, start,
                           pos < bytes.size() ? std::string("expected ") + what
                                              : std::string("file ends before ") + what);
    }
    return v;
  };
  while (true) {
    const std::size_t header = pos;
    if (bytes.size() - pos < 2 || bytes[pos] != 'P' ||
        (bytes[pos + 1] != '2' && bytes[pos + 1] != '5')) {
      detail::fail_at_byte(source, pos, "not a PGM image: expected 'P2' or 'P5'");
    }
    const bool binary = bytes[pos + 1] == '5';
    pos += 2;
    const std::uint64_t cols = number("width", kMaxImageValues);
    const std::uint64_t rows = number("height", kMaxImageValues);
    const std::uint64_t maxval = number("maxval", 65535);
    if (maxval == 0) detail::fail_at_byte(source, pos, "maxval must be in [1, 65535]");
    const std::uint64_t frames = static_cast<std::uint64_t>(out.frames) + 1;
    detail::check_size(source, frames, rows, cols, header);
    if (out.frames > 0 && (static_cast<Eigen::Index>(rows) != out.rows ||
                           static_cast<Eigen::Index>(cols) != out.cols)) {
      detail::fail_at_byte(source, header, "frame size differs from the first image's");
    }
    out.rows = static_cast<Eigen::Index>(rows);
    out.cols = static_cast<Eigen::Index>(cols);
    const std::uint64_t n = rows * cols;
    if (binary) {
      if (pos >= bytes.size()) detail::fail_at_byte(source, pos, "file ends before the pixels");
      const char sep = bytes[pos];
      if (sep != ' ' && sep != '\t' && sep != '\n' && sep != '\r') {
        detail::fail_at_byte(source, pos, "expected one whitespace byte after maxval");
      }
      ++pos;
      const std::uint64_t width = maxval > 255 ? 2 : 1;
      if ((bytes.size() - pos) / width < n) {
        detail::fail_at_byte(source, bytes.size(),
                             "truncated: " + std::to_string(n) + " pixels of " +
                                 std::to_string(width) + " byte(s) need " +
                                 std::to_string(n * width) + " bytes, " +
                                 std::to_string(bytes.size() - pos) + " remain");
      }
      for (std::uint64_t i = 0; i < n; ++i) {
        std::uint64_t v = static_cast<unsigned char>(bytes[pos]);
        if (width == 2) v = (v << 8) | static_cast<unsigned char>(bytes[pos + 1]);
        if (v > maxval) {
          detail::fail_at_byte(
              source, pos,
              "pixel value " + std::to_string(v) + " exceeds maxval " + std::to_string(maxval));
        }
        out.values.push_back(static_cast<double>(v));
        pos += width;
      }
    } else {
      for (std::uint64_t i = 0; i < n; ++i) {
        const std::size_t at = pos;
        const std::uint64_t v = number("a pixel value", 65535);
        if (v > maxval) {
          detail::fail_at_byte(
              source, at,
              "pixel value " + std::to_string(v) + " exceeds maxval " + std::to_string(maxval));
        }
        out.values.push_back(static_cast<double>(v));
      }
    }
    out.frames += 1;
    skip_space();
    if (pos >= bytes.size()) break;
  }
  return out;
}

/// Parses a NumPy .npy file (format versions 1.0, 2.0 and 3.0): a 2-D array (rows, cols) or a
/// 3-D stack (frames, rows, cols) of integers ('u1', 'i1', 'u2', 'i2', 'u4', 'i4', 'u8', 'i8')
/// or floats ('f4', 'f8') in either byte order, C or Fortran order (see io/npy.hpp).
/// Non-finite floats are refused. Throws IoError with the byte offset of the first error.
template <class = void>
inline ImageStack parse_npy(std::string_view bytes, const std::string& source = "<npy>") {
  const NpyArray a = parse_npy_header(bytes, source, kMaxImageValues);
  if (a.shape.size() != 2 && a.shape.size() != 3) {
    detail::fail_at_byte(source, a.shape_at,
                         "expected a 2-D image or a 3-D stack of frames, got " +
                             std::to_string(a.shape.size()) + " dimension(s)");
  }
  ImageStack out;
  const std::uint64_t frames = a.shape.size() == 3 ? a.shape[0] : 1;
  const std::uint64_t rows = a.shape[a.shape.size() - 2];
  const std::uint64_t cols = a.shape[a.shape.size() - 1];
  detail::check_size(source, frames, rows, cols, a.shape_at);
  out.frames = static_cast<Eigen::Index>(frames);
  out.rows = static_cast<Eigen::Index>(rows);
  out.cols = static_cast<Eigen::Index>(cols);
  out.values.resize(a.count);
  for (std::uint64_t k = 0; k < a.count; ++k) {
    const double v = a.value(bytes, k);
    const std::uint64_t i = a.flat_index(k);
    if (!std::isfinite(v)) {  // name the pixel: (frame, row, column)
      detail::fail_at_byte(source, a.data_at + k * static_cast<std::uint64_t>(a.width),
                           "pixel (row " + std::to_string(i / cols % rows) + ", column " +
                               std::to_string(i % cols) + ") of frame " +
                               std::to_string(i / (rows * cols)) + " is not finite (" +
                               (std::isnan(v) ? "nan"
                                : v > 0       ? "inf"
                                              : "-inf") +
                               ")");
    }
    out.values[i] = v;
  }
  return out;
}

/// Reads an image or a stack from a file, choosing the format by extension (.csv, .pgm, .npy).
template <class = void>
inline ImageStack read_image(const std::string& path) {
  const std::string ext = extension(path);
  if (ext == ".csv" || ext == ".txt") return parse_image_csv(read_file(path), path);
  if (ext == ".pgm") return parse_pgm(read_file(path), path);
  if (ext == ".npy") return parse_npy(read_file(path), path);
  throw IoError(path, "unknown image format '" + ext + "': expected .csv, .pgm or .npy");
}

/// Encodes an image as binary PGM (P5): values are mapped linearly from [lo, hi] to
/// [0, maxval] (clamped, rounded); maxval 255 gives 8-bit, up to 65535 gives 16-bit samples.
template <class = void>
inline std::string encode_pgm(const image::ImageView& img, double lo = 0.0, double hi = 255.0,
                              int maxval = 255) {
  if (maxval < 1 || maxval > 65535) throw std::invalid_argument("encode_pgm: maxval in [1, 65535]");
  if (!(hi > lo)) throw std::invalid_argument("encode_pgm: hi must exceed lo");
  std::string out = "P5\n" + std::to_string(img.cols()) + " " + std::to_string(img.rows()) + "\n" +
                    std::to_string(maxval) + "\n";
  for (Eigen::Index r = 0; r < img.rows(); ++r) {
    for (Eigen::Index c = 0; c < img.cols(); ++c) {
      const double t = std::clamp((img(r, c) - lo) / (hi - lo), 0.0, 1.0);
      const auto v = static_cast<unsigned>(std::lround(t * maxval));
      if (maxval > 255) out.push_back(static_cast<char>(v >> 8));
      out.push_back(static_cast<char>(v & 0xFF));
    }
  }
  return out;
}

/// Element type of an NPY file written by encode_npy.
enum class NpyDtype {
  f8,  ///< '<f8', any finite or non-finite double
  u1,  ///< '|u1', integers 0..255 (8-bit sensor images; an eighth of the size)
  u2,  ///< '<u2', integers 0..65535
};

/// Encodes frames as NPY version 1.0, shape (rows, cols) for one frame or (frames, rows, cols).
/// For the integer types every value must be an integer in the type's range; otherwise throws
/// std::invalid_argument naming the first offending value's index.
inline std::string encode_npy(const ImageStack& stack, NpyDtype dtype = NpyDtype::f8) {
  const char* descr = dtype == NpyDtype::f8 ? "<f8" : dtype == NpyDtype::u1 ? "|u1" : "<u2";
  const double top = dtype == NpyDtype::u1 ? 255.0 : 65535.0;
  if (dtype != NpyDtype::f8) {
    for (std::size_t i = 0; i < stack.values.size(); ++i) {
      const double v = stack.values[i];
      if (!(v >= 0.0 && v <= top && v == std::floor(v))) {
        throw std::invalid_argument("encode_npy: value " + std::to_string(v) + " at index " +
                                    std::to_string(i) + " does not fit dtype " + descr);
      }
    }
  }
  std::string shape = "(";
  if (stack.frames != 1) shape += std::to_string(stack.frames) + ", ";
  shape += std::to_string(stack.rows) + ", " + std::to_string(stack.cols) + ")";
  std::string out = detail_npy::header_v1(descr, shape);
  for (double v : stack.values) {
    if (dtype == NpyDtype::u1) {
      out.push_back(static_cast<char>(static_cast<std::uint8_t>(v)));
    } else if (dtype == NpyDtype::u2) {
      const auto u = static_cast<std::uint16_t>(v);
      out.push_back(static_cast<char>(u & 0xFF));
      out.push_back(static_cast<char>(u >> 8));
    } else {
      const auto bits = std::bit_cast<std::uint64_t>(v);
      for (int b = 0; b < 8; ++b) out.push_back(static_cast<char>((bits >> (8 * b)) & 0xFF));
    }
  }
  return out;
}

/// Encodes one image as CSV (full precision, one row per line).
template <class = void>
inline std::string encode_image_csv(const image::ImageView& img) {
  std::string out;
  char buf[32];
  for (Eigen::Index r = 0; r < img.rows(); ++r) {
    for (Eigen::Index c = 0; c < img.cols(); ++c) {
      if (c > 0) out.push_back(',');
      const auto res = std::to_chars(buf, buf + sizeof buf, img(r, c));
      out.append(buf, res.ptr);
    }
    out.push_back('\n');
  }
  return out;
}

}  // namespace taxel::io
