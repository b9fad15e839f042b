// SPDX-License-Identifier: MIT
// PNG output through libpng's simplified API. This header needs libpng at link time: link the
// CMake target taxel::png (defined when libpng is found) or add -lpng.
#pragma once

#include <png.h>

#include <cstdint>
#include <string>

#include "taxel/core/error.hpp"
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

/// Reads a PNG file into an RGB picture (any PNG colour type is converted). Throws IoError.
template <class = void>
inline RgbImage read_png(const std::string& path) {
  png_image desc{};
  desc.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&desc, path.c_str()) == 0) {
    throw IoError(path, std::string("PNG read failed: ") + desc.message);
  }
  desc.format = PNG_FORMAT_RGB;
  RgbImage img(static_cast<Eigen::Index>(desc.height), static_cast<Eigen::Index>(desc.width), 0);
  if (png_image_finish_read(&desc, nullptr, img.data.data(), static_cast<png_int_32>(img.cols * 3),
                            nullptr) == 0) {
    const std::string why = desc.message;
    png_image_free(&desc);
    throw IoError(path, "PNG read failed: " + why);
  }
  return img;
}

}  // namespace taxel::io
