// SPDX-License-Identifier: MIT
#include <taxel/taxel.hpp>

#include "units.hpp"

int unit_io() {
  const auto data = taxel::io::parse_ply(
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n0 0 0\n1 2 3\n",
      "inline.ply");
  return data.cloud.size() == 2 && data.cloud.points[1].z() == 3.0 ? 0 : 1;
}
