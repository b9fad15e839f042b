// SPDX-License-Identifier: MIT
// Umbrella header of taxel::core.
#pragma once

#include "taxel/core/assert.hpp"
#include "taxel/core/concepts.hpp"
#include "taxel/core/contact.hpp"
#include "taxel/core/deferred.hpp"
#include "taxel/core/error.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/core/status.hpp"
#include "taxel/core/types.hpp"
#include "taxel/version.hpp"
