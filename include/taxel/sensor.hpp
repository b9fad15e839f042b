// SPDX-License-Identifier: MIT
// Umbrella header of taxel::sensor: pad geometry and the readings-to-contacts model.
#pragma once

#include "taxel/sensor/contacts.hpp"
#include "taxel/sensor/pad.hpp"
