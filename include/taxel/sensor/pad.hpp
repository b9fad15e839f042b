// SPDX-License-Identifier: MIT
// A tactile pad: its tactel layout and how its readings relate to indentation, with the noise
// of the readings and of the pad's pose. Shared by the simulator, the drivers and the tools.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>

#include "taxel/core/types.hpp"

namespace taxel::sensor {

/// Tactel layout of a pad. Tactel (r, c) sits at x = (c - (cols - 1) / 2) pitch,
/// y = (r - (rows - 1) / 2) pitch, z = 0 in the pad frame; the sensing face looks along +z
/// (into the touched object). Default: a Weiss DSA 9205-like matrix, 14 rows x 6 columns at
/// 3.4 mm.
struct PadGeometry {
  int rows = 14;          ///< tactel rows, >= 1
  int cols = 6;           ///< tactel columns, >= 1
  double pitch = 3.4e-3;  ///< centre-to-centre distance [m], in [1e-6, 1]

  /// Centre of tactel (r, c) in the pad frame [m].
  Vec3d tactel(int r, int c) const {
    return {(c - 0.5 * (cols - 1)) * pitch, (r - 0.5 * (rows - 1)) * pitch, 0.0};
  }
};

/// How a pad turns indentation into readings, and the noise of the reading and of the pose.
/// The pad is soft and the object rigid: a tactel pressed `d` into the object reads
/// `d / full_scale_depth * (levels - 1)` counts (a linear, Winkler-foundation model) plus
/// Gaussian depth noise of `sigma_normal`, rounded and clipped at `levels - 1`; readings below
/// `threshold` are reported as zero (the noise floor), so they are censored, not missing.
struct SensorModel {
  PadGeometry geometry;            ///< Rows, columns and pitch of the pad.
  double full_scale_depth = 3e-3;  ///< indentation that saturates a tactel [m], in (0, 1]
  int levels = 4096;               ///< reading levels (12-bit like the DSA), >= 2
  int threshold = 8;               ///< readings below this are zero (noise floor), >= 1
  /// Depth noise of a touching tactel, along the normal [m], in [0, 1].
  double sigma_normal = 0.3e-3;
  double sigma_position = 0.2e-3;  ///< kinematic translation noise of the pad [m], in [0, 1]
  /// Kinematic rotation noise of the pad, per frame: angle standard deviation [rad], in [0, pi].
  double sigma_tilt = 0.02;

  /// Depth of one reading count [m].
  double depth_per_count() const { return full_scale_depth / double(levels - 1); }

  /// Throws std::invalid_argument naming the first parameter out of range. The lengths are
  /// bounded by a metre (and the pitch below by a micrometre): no tactile pad comes near, a
  /// value beyond is a unit mistaken, and within these bounds every variance the contacts state
  /// stays finite (beyond them, a depth noise of 1e300 m overflows to infinity).
  void validate() const {
    const auto need = [](bool ok, const char* what) {
      if (!ok) throw std::invalid_argument(std::string("SensorModel: ") + what);
    };
    need(geometry.rows >= 1 && geometry.cols >= 1, "rows and cols must be >= 1");
    need(geometry.rows <= 4096 && geometry.cols <= 4096, "rows and cols must be <= 4096");
    need(geometry.pitch >= 1e-6 && geometry.pitch <= 1.0,
         "pitch must be in [1e-6, 1] m (a length in millimetres given as metres?)");
    need(full_scale_depth > 0 && full_scale_depth <= 1.0,
         "full_scale_depth must be in (0, 1] m (a length in millimetres given as metres?)");
    need(levels >= 2 && levels <= 65536, "levels must be in [2, 65536]");
    need(threshold >= 1 && threshold < levels, "threshold must be in [1, levels)");
    need(sigma_normal >= 0 && sigma_normal <= 1.0, "sigma_normal must be in [0, 1] m");
    need(sigma_position >= 0 && sigma_position <= 1.0, "sigma_position must be in [0, 1] m");
    need(sigma_tilt >= 0 && sigma_tilt <= std::numbers::pi, "sigma_tilt must be in [0, pi] rad");
  }
};

/// Gauss-Legendre nodes on [-1/2, 1/2] for 1 to 4 points (row n - 1), and their weights
/// (summing to 1): a tactel's footprint (its pitch x pitch square) is integrated
/// on them, n per side.
inline constexpr double kGaussNode[4][4] = {
    {0.0},
    {-0.28867513459481287, 0.28867513459481287},
    {-0.3872983346207417, 0.0, 0.3872983346207417},
    {-0.43056815579702629, -0.16999052179242813, 0.16999052179242813, 0.43056815579702629}};
/// See kGaussNode.
inline constexpr double kGaussWeight[4][4] = {
    {1.0},
    {0.5, 0.5},
    {0.2777777777777778, 0.4444444444444444, 0.2777777777777778},
    {0.17392742256872692, 0.32607257743127307, 0.32607257743127307, 0.17392742256872692}};

/// Readings of one pad as a row-major rows x cols matrix of counts.
using PadMatrix = Eigen::Array<std::uint16_t, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// Contacts from a reading: one per active tactel, or one per pad and frame (from a quadric
/// fitted to the pad's depth map; a frame whose active tactels do not determine a quadric, fewer
/// than six or in one or two rows, or whose depths the quadric does not fit, gives one per
/// active tactel).
enum class ContactMode { per_tactel, per_pad };

}  // namespace taxel::sensor
