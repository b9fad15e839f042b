// SPDX-License-Identifier: MIT
// Umbrella header of taxel::sensor: pad geometry, the readings-to-contacts model and
// stacks of readings with their poses.
#pragma once

#include "taxel/sensor/contacts.hpp"
#include "taxel/sensor/pad.hpp"
#include "taxel/sensor/readings.hpp"
