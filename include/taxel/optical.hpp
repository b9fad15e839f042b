// SPDX-License-Identifier: MIT
// Umbrella header of taxel::optical: camera-based tactile sensors (GelSight and DIGIT class),
// from frames through a ball-press calibration and Poisson integration to height maps and
// contacts.
#pragma once

#include "taxel/optical/calibration.hpp"
#include "taxel/optical/calibration_file.hpp"
#include "taxel/optical/markers.hpp"
#include "taxel/optical/poisson.hpp"
#include "taxel/optical/reconstruct.hpp"
#include "taxel/optical/shading.hpp"
#include "taxel/optical/tracking.hpp"
#include "taxel/optical/types.hpp"
