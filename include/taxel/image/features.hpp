// SPDX-License-Identifier: MIT
// Feature vectors of the second paper: the 11 regional descriptors (step 3), the 23 edged /
// edgeless features (step 5) and the hybrid vector (step 7: M*N gradient magnitudes of the
// reconstruction followed by the 11 descriptors).
#pragma once

#include <Eigen/Core>
#include <array>
#include <string_view>

#include "taxel/image/regionprops.hpp"
#include "taxel/image/types.hpp"

namespace taxel::image {

/// Length of the regional feature vector.
inline constexpr int kRegionalFeatures = 11;
/// Length of the edged/edgeless feature vector.
inline constexpr int kEdgeFeatures = 23;

/// Names of the 11 regional features, in order (paper's Table 1 symbols).
inline constexpr std::array<std::string_view, kRegionalFeatures> kRegionalFeatureNames = {
    "Ar", "xC", "yC", "xBB", "yBB", "LBB", "WBB", "CH", "Ecc", "EN", "Or"};

/// Names of the 23 edged/edgeless features, in order.
inline constexpr std::array<std::string_view, kEdgeFeatures> kEdgeFeatureNames = {
    "Ar",    "xC",  "yC",  "xBB",  "yBB",   "LBB",   "WBB",   "CH",
    "Ecc",   "EN",  "Or",  "Imax", "Imin",  "Imean", "Area1", "Area2",
    "Area3", "Gm1", "Gm2", "Gm3",  "Gdir1", "Gdir2", "Gdir3"};

/// The 11 regional features of the union of the HPRs, in the paper's order:
/// area, centroid x and y, bounding-box upper-left x and y, bounding-box length (width, along
/// x) and width (height, along y), convex area (pixel count), eccentricity, Euler number
/// (8-connected), orientation (degrees). An empty region gives zeros.
template <class = void>
inline void regional_features(const RegionProps& p, Eigen::Ref<Eigen::VectorXd> out) {
  out(0) = p.area;
  out(1) = p.centroid.x();
  out(2) = p.centroid.y();
  out(3) = p.bounding_box(0);
  out(4) = p.bounding_box(1);
  out(5) = p.bounding_box(2);
  out(6) = p.bounding_box(3);
  out(7) = p.convex_area;
  out(8) = p.eccentricity;
  out(9) = p.euler_number;
  out(10) = p.orientation;
}

}  // namespace taxel::image
