// SPDX-License-Identifier: MIT
// Umbrella header of taxel::registration: ICP targets, error policies, robust kernels, ICP and
// recognition among object models.
#pragma once

#include "taxel/registration/icp.hpp"
#include "taxel/registration/kernels.hpp"
#include "taxel/registration/model.hpp"
#include "taxel/registration/object_library.hpp"
#include "taxel/registration/target.hpp"
