// SPDX-License-Identifier: MIT
// Umbrella header: all of taxel.
#pragma once

#include "taxel/core.hpp"
#include "taxel/fusion.hpp"
#include "taxel/image.hpp"
#include "taxel/index.hpp"
#include "taxel/io.hpp"
#include "taxel/learn.hpp"
#include "taxel/optical.hpp"
#include "taxel/registration.hpp"
#include "taxel/sensor.hpp"
#include "taxel/shape.hpp"
#include "taxel/sim.hpp"
