// SPDX-License-Identifier: MIT
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_sensor() {
  const taxel::sensor::PadGeometry pad;
  return pad.rows > 0 && pad.cols > 0 ? 0 : 1;
}
