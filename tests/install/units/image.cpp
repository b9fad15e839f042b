// SPDX-License-Identifier: MIT
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_image() {
  taxel::image::ImageD img = taxel::image::ImageD::Zero(32, 32);
  img.block(10, 10, 6, 6).setConstant(100.0);
  img.block(12, 12, 2, 2).setConstant(200.0);
  taxel::image::Recognizer<> rec(32, 32);
  const auto& r = rec.recognize(img);
  return r.ok() ? 0 : 1;
}
