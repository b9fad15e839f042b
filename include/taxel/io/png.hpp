// SPDX-License-Identifier: MIT
// PNG through libpng's simplified API: pictures out and in, and greyscale pressure images in.
// This header needs libpng at link time: link the CMake target taxel::png (defined when libpng
// is found) or add -lpng.
#pragma once

#include <png.h>

#include <cstdint>
#include <string>
#include <string_view>

#include "taxel/core/error.hpp"
#include "taxel/io/image.hpp"
#include "taxel/io/picture.hpp"

namespace taxel::io {

/// Writes an RGB picture as PNG. Throws IoError naming the file and libpng's message.
inline void write_png(const std::string& path, const RgbImage& img) {
  if (img.rows <= 0 || img.cols <= 0 ||
      img.data.size() != static_cast<std::size_t>(img.rows * img.cols * 3)) {
    throw IoError(path, "cannot write an empty or inconsistent picture");
  }
  png_image desc{};
  desc.version = PNG_IMAGE_VERSION;
  desc.width = static_cast<png_uint_32>(img.cols);
  desc.height = static_cast<png_uint_32>(img.rows);
  desc.format = PNG_FORMAT_RGB;
  if (png_image_write_to_file(&desc, path.c_str(), 0, img.data.data(),
                              static_cast<png_int_32>(img.cols * 3), nullptr) == 0) {
    const std::string why = desc.message;
    png_image_free(&desc);
    throw IoError(path, "PNG write failed: " + why);
  }
}

namespace detail_png {

// Finishes reading a begun png_image as RGB; throws IoError naming `source`.
inline RgbImage finish_rgb(png_image& desc, const std::string& source) {
  desc.format = PNG_FORMAT_RGB;
  RgbImage img(static_cast<Eigen::Index>(desc.height), static_cast<Eigen::Index>(desc.width), 0);
  if (png_image_finish_read(&desc, nullptr, img.data.data(), static_cast<png_int_32>(img.cols * 3),
                            nullptr) == 0) {
    const std::string why = desc.message;
    png_image_free(&desc);
    throw IoError(source, "PNG read failed: " + why);
  }
  return img;
}

}  // namespace detail_png

/// Reads a PNG file into an RGB picture (any PNG colour type is converted). Throws IoError.
template <class = void>
inline RgbImage read_png(const std::string& path) {
  png_image desc{};
  desc.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&desc, path.c_str()) == 0) {
    throw IoError(path, std::string("PNG read failed: ") + desc.message);
  }
  return detail_png::finish_rgb(desc, path);
}

/// Decodes PNG bytes into an RGB picture (any PNG colour type is converted); `source` names
/// them in errors. Throws IoError.
template <class = void>
inline RgbImage decode_png(std::string_view bytes, const std::string& source = "<png>") {
  png_image desc{};
  desc.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&desc, bytes.data(), bytes.size()) == 0) {
    throw IoError(source, std::string("PNG read failed: ") + desc.message);
  }
  return detail_png::finish_rgb(desc, source);
}

/// Reads a greyscale PNG (8 or 16 bits per sample) as a one-frame pressure image, the samples as
/// stored: 0..255 or 0..65535. (A file with a gamma or sRGB chunk is converted by libpng: an
/// 8-bit file to sRGB, a 16-bit one to linear; files from sensors and numpy carry none.) Throws
/// IoError for an unreadable file, a colour image or one with an alpha channel, naming the
/// file.
template <class = void>
inline ImageStack read_png_image(const std::string& path);

/// As read_png_image, from the bytes of a PNG file in memory; `path` names it in errors.
template <class = void>
inline ImageStack decode_png_image(std::string_view bytes, const std::string& path = "<png>") {
  png_image desc{};
  desc.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_memory(&desc, bytes.data(), bytes.size()) == 0) {
    throw IoError(path, std::string("PNG read failed: ") + desc.message);
  }
  const auto refuse = [&](const std::string& why) {
    png_image_free(&desc);
    throw IoError(path, why);
  };
  if ((desc.format & PNG_FORMAT_FLAG_COLOR) != 0) {
    refuse("a colour PNG; a pressure image must be greyscale (8 or 16 bits)");
  }
  if ((desc.format & PNG_FORMAT_FLAG_ALPHA) != 0) {
    refuse("a PNG with an alpha channel; a pressure image must be plain greyscale");
  }
  try {
    detail::check_size(path, 1, desc.height, desc.width, 16);  // IHDR's width is at byte 16
  } catch (...) {
    png_image_free(&desc);
    throw;
  }
  const bool wide = (desc.format & PNG_FORMAT_FLAG_LINEAR) != 0;  // 16 bits per sample
  desc.format = wide ? PNG_FORMAT_LINEAR_Y : PNG_FORMAT_GRAY;
  ImageStack out;
  out.frames = 1;
  out.rows = static_cast<Eigen::Index>(desc.height);
  out.cols = static_cast<Eigen::Index>(desc.width);
  const std::size_t n = static_cast<std::size_t>(desc.height) * desc.width;
  std::vector<std::uint16_t> wide_samples(wide ? n : 0);
  std::vector<std::uint8_t> narrow_samples(wide ? 0 : n);
  void* buffer =
      wide ? static_cast<void*>(wide_samples.data()) : static_cast<void*>(narrow_samples.data());
  if (png_image_finish_read(&desc, nullptr, buffer, 0, nullptr) == 0) {
    const std::string why = desc.message;
    png_image_free(&desc);
    throw IoError(path, "PNG read failed: " + why);
  }
  out.values.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    out.values[i] = wide ? double(wide_samples[i]) : double(narrow_samples[i]);
  }
  return out;
}

template <class>
inline ImageStack read_png_image(const std::string& path) {
  return decode_png_image(read_file(path), path);
}

}  // namespace taxel::io
