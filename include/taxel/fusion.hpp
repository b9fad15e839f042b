// SPDX-License-Identifier: MIT
// Umbrella header of taxel::fusion.
#pragma once

#include "taxel/fusion/average.hpp"
#include "taxel/fusion/concepts.hpp"
#include "taxel/fusion/contact_cloud.hpp"
#include "taxel/fusion/kalman.hpp"
#include "taxel/fusion/raw.hpp"
#include "taxel/fusion/surfel.hpp"
