// SPDX-License-Identifier: MIT
// Fuzzes the CSV, PGM and NPY image readers with arbitrary bytes (the first byte picks the
// reader; NPY and PGM inputs start with a valid magic half of the time to get past it). A reader
// must either throw taxel::IoError or return a consistent, finite image; a returned image is
// then run through the whole pressure-image chain, which must not crash.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <taxel/image.hpp>
#include <taxel/io/image.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int which = data[0] % 6;
  std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  if (which == 3) bytes = std::string("\x93NUMPY\x01\x00", 8) + bytes;
  if (which == 4) bytes = "P5\n" + bytes;
  if (which == 5) bytes = "P2\n" + bytes;
  taxel::io::ImageStack s;
  try {
    switch (which) {
      case 0:
        s = taxel::io::parse_image_csv(bytes);
        break;
      case 1:
      case 4:
      case 5:
        s = taxel::io::parse_pgm(bytes);
        break;
      default:
        s = taxel::io::parse_npy(bytes);
        break;
    }
  } catch (const taxel::IoError&) {
    return 0;
  }
  if (s.frames < 1 || s.rows < 1 || s.cols < 1 ||
      s.values.size() != static_cast<std::size_t>(s.frames * s.rows * s.cols)) {
    std::abort();
  }
  for (double v : s.values) {
    if (!std::isfinite(v)) std::abort();
  }
  if (s.rows * s.cols <= 4096) {
    taxel::image::Recognizer<> rec(s.rows, s.cols);
    const auto& r = rec.recognize(s.frame(0));
    if (r.ok() && !r.hybrid.allFinite()) std::abort();
  }
  return 0;
}
