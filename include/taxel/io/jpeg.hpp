// SPDX-License-Identifier: MIT
// JPEG through libjpeg (libjpeg-turbo on Debian): pictures in, for camera-based tactile
// sensors' frames. This header needs libjpeg at link time: link the CMake target taxel::jpeg
// (defined when libjpeg is found) or add -ljpeg.
#pragma once

#include <csetjmp>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

// jpeglib.h needs FILE and size_t declared before it.
#include <jpeglib.h>
// (after jpeglib.h: the message codes, JWRN_JPEG_EOF among them)
#include <jerror.h>

#include "taxel/core/error.hpp"
#include "taxel/io/file.hpp"
#include "taxel/io/picture.hpp"

namespace taxel::io {

namespace detail_jpeg {

// libjpeg reports a fatal error by calling error_exit, which must not return: it jumps back
// to decode() with the message kept. A warning that the data ended early (a truncated file,
// which libjpeg would otherwise fill with grey) is made fatal the same way; other warnings
// (extraneous bytes, which some cameras write) are let through.
struct Errors {
  jpeg_error_mgr mgr;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

inline void fail(j_common_ptr info) {
  auto* e = reinterpret_cast<Errors*>(info->err);
  (*info->err->format_message)(info, e->message);
  std::longjmp(e->jump, 1);
}

inline void warn(j_common_ptr info, int level) {
  if (level < 0 && info->err->msg_code == JWRN_JPEG_EOF) fail(info);
}

// Decodes into *out (allocated here). Only C objects live in this frame across the jumps, and
// *out is the caller's, so no destructor is skipped. Returns false with `message` set.
inline bool decode(const unsigned char* data, std::size_t size, RgbImage* out,
                   std::string* message) {
  jpeg_decompress_struct info{};
  Errors errors{};
  info.err = jpeg_std_error(&errors.mgr);
  errors.mgr.error_exit = fail;
  errors.mgr.emit_message = warn;
  if (setjmp(errors.jump) != 0) {
    message->assign(errors.message);
    jpeg_destroy_decompress(&info);
    return false;
  }
  jpeg_create_decompress(&info);
  jpeg_mem_src(&info, data, static_cast<unsigned long>(size));
  jpeg_read_header(&info, TRUE);
  info.out_color_space = JCS_RGB;  // greyscale and YCbCr are converted; CMYK is refused
  jpeg_start_decompress(&info);
  if (info.output_components != 3) {
    message->assign("not an RGB or greyscale JPEG");
    jpeg_destroy_decompress(&info);
    return false;
  }
  out->rows = static_cast<Eigen::Index>(info.output_height);
  out->cols = static_cast<Eigen::Index>(info.output_width);
  out->data.assign(std::size_t{info.output_height} * info.output_width * 3, 0);
  while (info.output_scanline < info.output_height) {
    JSAMPROW row = out->data.data() + std::size_t{info.output_scanline} * info.output_width * 3;
    jpeg_read_scanlines(&info, &row, 1);
  }
  jpeg_finish_decompress(&info);
  jpeg_destroy_decompress(&info);
  return true;
}

}  // namespace detail_jpeg

/// Decodes JPEG bytes into an RGB picture (greyscale is expanded to RGB). Throws IoError naming
/// `source` and libjpeg's message for data that is not a JPEG, is truncated or is CMYK.
template <class = void>
RgbImage decode_jpeg(std::string_view bytes, const std::string& source = "<jpeg>") {
  if (bytes.size() < 3 || static_cast<unsigned char>(bytes[0]) != 0xFF ||
      static_cast<unsigned char>(bytes[1]) != 0xD8) {
    throw IoError(source, "not a JPEG file (no start-of-image marker)");
  }
  RgbImage img;
  std::string why;
  if (!detail_jpeg::decode(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), &img,
                           &why)) {
    throw IoError(source, "JPEG read failed: " + why);
  }
  return img;
}

/// Reads a JPEG file into an RGB picture. Throws IoError (see decode_jpeg).
template <class = void>
RgbImage read_jpeg(const std::string& path) {
  return decode_jpeg(read_file(path), path);
}

}  // namespace taxel::io
