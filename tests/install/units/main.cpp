// SPDX-License-Identifier: MIT
#include <cstdio>
#include <taxel/taxel.hpp>

#include "units.hpp"

int main() {
  const int failed = unit_fusion() + unit_index() + unit_registration() + unit_image() +
                     unit_learn() + unit_io() + unit_sim() + unit_sensor() + unit_all();
  std::printf("taxel %s, ten translation units: %d failed checks\n", TAXEL_VERSION_STRING, failed);
  return failed == 0 ? 0 : 1;
}
