// SPDX-License-Identifier: MIT
// Umbrella header: all of taxel.
#pragma once

#include "taxel/core.hpp"
