// SPDX-License-Identifier: MIT
// Umbrella header of taxel::sim.
#pragma once

#include "taxel/sim/compression.hpp"
#include "taxel/sim/contact_stream.hpp"
#include "taxel/sim/exploration.hpp"
#include "taxel/sim/metrics.hpp"
#include "taxel/sim/optical.hpp"
#include "taxel/sim/palm_grasp.hpp"
#include "taxel/sim/sampling.hpp"
#include "taxel/sim/sensor.hpp"
#include "taxel/sim/shapes.hpp"
#include "taxel/sim/sliding.hpp"
