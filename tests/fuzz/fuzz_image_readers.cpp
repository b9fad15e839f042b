// SPDX-License-Identifier: MIT
// Fuzzes the CSV, PGM and NPY image readers with arbitrary bytes (the first byte picks the
// reader; NPY and PGM inputs start with a valid magic half of the time to get past it). A reader
// must either throw taxel::IoError or return a consistent, finite image; a returned image is
// then run through the whole pressure-image chain, which must not crash, with a configuration
// drawn from the input's last six bytes over the ranges RecognizerConfig accepts (k 2-255,
// either polarity and connectivity, any minimum area, the histogram path on or off, both
// gradient sources, RecEdged's step factor from 0 to 1e6 of either sign and every switch,
// RecEdgeless's degrees 0-6, healing and height source, both background fractions in [0, 1]).
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <taxel/image.hpp>
#include <taxel/io/image.hpp>

#include "byte_range.hpp"

namespace {

// The recognizer's configuration from six bytes.
taxel::image::RecognizerConfig draw_config(const std::uint8_t* b) {
  namespace ti = taxel::image;
  ti::RecognizerConfig c;
  c.segmentation.k = 2 + b[0] % 254;
  c.segmentation.polarity =
      b[1] & 1 ? ti::Polarity::dark_is_pressure : ti::Polarity::high_is_pressure;
  c.segmentation.connectivity = b[1] & 2 ? ti::Connectivity::four : ti::Connectivity::eight;
  c.segmentation.min_area = b[1] & 4 ? 0 : (b[2] & 128 ? 1 << (b[2] & 31) : b[2]);
  c.segmentation.histogram_levels = b[1] & 8 ? 0 : (b[1] & 16 ? 1 << 24 : 65536);
  c.gradient_source = b[1] & 32 ? ti::GradientSource::quantised : ti::GradientSource::raw;
  const double k = b[3] == 0 ? 0.0 : taxel::fuzz::log_range(b[3], 1e-300, 1e6);
  c.edged.k = b[1] & 64 ? -k : k;
  c.edged.background_fraction = (b[4] & 15) / 15.0;
  c.edged.swap_edge_condition = (b[4] & 16) != 0;
  c.edged.fill_whole_row = (b[4] & 32) != 0;
  c.edged.keep_level_on_skipped_rows = (b[4] & 64) != 0;
  c.edged.postprocess = static_cast<ti::PostProcess>(b[5] % 3);
  c.edgeless.background_fraction = (b[5] / 3 % 16) / 15.0;
  c.edgeless.degree = b[2] % 7;
  c.edgeless.healing = static_cast<ti::Healing>(b[0] % 3);
  c.edgeless.source = b[1] & 128 ? ti::HeightSource::quantised : ti::HeightSource::raw;
  return c;
}

}  // namespace

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
    taxel::image::Recognizer<> rec(
        s.rows, s.cols,
        size >= 7 ? draw_config(data + size - 6) : taxel::image::RecognizerConfig{});
    const auto& r = rec.recognize(s.frame(0));
    if (r.ok() && !r.hybrid.allFinite()) std::abort();
  }
  return 0;
}
