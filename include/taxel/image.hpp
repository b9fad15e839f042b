// SPDX-License-Identifier: MIT
// Umbrella header of taxel::image: pressure-image segmentation, region descriptors, gradients,
// reconstruction and feature vectors (the second paper's pipeline).
#pragma once

#include "taxel/image/components.hpp"
#include "taxel/image/features.hpp"
#include "taxel/image/gradient.hpp"
#include "taxel/image/kmeans.hpp"
#include "taxel/image/recognizer.hpp"
#include "taxel/image/reconstruction.hpp"
#include "taxel/image/regionprops.hpp"
#include "taxel/image/segmentation.hpp"
#include "taxel/image/types.hpp"
