// SPDX-License-Identifier: MIT
// Connected components of a mask (4- or 8-connected) and removal of small regions (MATLAB's
// bwareaopen).
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "taxel/image/types.hpp"

namespace taxel::image {

/// Connected-component labelling workspace. Labels are assigned in raster order (row by row)
/// from 1; MATLAB numbers in column order, so compare region properties, not label numbers.
/// Reusing one object for images of the same size allocates nothing.
class Components {
 public:
  Components() = default;
  /// Preallocates for `rows x cols` images.
  Components(Eigen::Index rows, Eigen::Index cols) { reserve(rows, cols); }

  /// Preallocates for `rows x cols` images.
  void reserve(Eigen::Index rows, Eigen::Index cols) {
    labels_.resize(rows, cols);
    parent_.reserve(static_cast<std::size_t>(rows * cols) + 1);
    remap_.reserve(static_cast<std::size_t>(rows * cols) + 1);
    area_.reserve(static_cast<std::size_t>(rows * cols) + 1);
  }

  /// Labels the non-zero pixels of `mask`; returns the number of components.
  /// Two raster passes with union-find over provisional labels.
  int compute(const MaskView& mask, Connectivity connectivity = Connectivity::eight) {
    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    labels_.resize(rows, cols);
    parent_.clear();
    parent_.push_back(0);
    const bool eight = connectivity == Connectivity::eight;
    for (Eigen::Index r = 0; r < rows; ++r) {
      const std::uint8_t* m = mask.data() + r * mask.outerStride();
      std::int32_t* lab = labels_.data() + r * cols;
      const std::int32_t* up = r > 0 ? lab - cols : nullptr;
      for (Eigen::Index c = 0; c < cols; ++c) {
        if (m[c] == 0) {
          lab[c] = 0;
          continue;
        }
        std::int32_t best = 0;
        auto see = [&](std::int32_t l) {
          if (l == 0) return;
          l = find(l);
          if (best == 0) {
            best = l;
          } else if (l != best) {
            const std::int32_t lo = std::min(l, best), hi = std::max(l, best);
            parent_[static_cast<std::size_t>(hi)] = lo;
            best = lo;
          }
        };
        if (c > 0) see(lab[c - 1]);
        if (up != nullptr) {
          see(up[c]);
          if (eight && c > 0) see(up[c - 1]);
          if (eight && c + 1 < cols) see(up[c + 1]);
        }
        if (best == 0) {
          best = static_cast<std::int32_t>(parent_.size());
          parent_.push_back(best);
        }
        lab[c] = best;
      }
    }
    // Second pass: final ids in raster order of each component's first pixel, and areas.
    remap_.assign(parent_.size(), 0);
    area_.assign(1, 0);
    count_ = 0;
    for (Eigen::Index i = 0; i < labels_.size(); ++i) {
      std::int32_t& l = labels_.data()[i];
      if (l == 0) continue;
      const auto root = static_cast<std::size_t>(find(l));
      if (remap_[root] == 0) {
        remap_[root] = ++count_;
        area_.push_back(0);
      }
      l = remap_[root];
      ++area_[static_cast<std::size_t>(l)];
    }
    return count_;
  }

  /// Number of components of the last `compute`.
  [[nodiscard]] int count() const noexcept { return count_; }
  /// Label image of the last `compute` (0 = background).
  [[nodiscard]] const Labels& labels() const noexcept { return labels_; }
  /// Pixel count of component `id` (1-based).
  [[nodiscard]] std::int32_t area(int id) const noexcept {
    return area_[static_cast<std::size_t>(id)];
  }

 private:
  std::int32_t find(std::int32_t l) noexcept {
    while (parent_[static_cast<std::size_t>(l)] != l) {
      const std::int32_t p = parent_[static_cast<std::size_t>(l)];
      parent_[static_cast<std::size_t>(l)] = parent_[static_cast<std::size_t>(p)];
      l = p;
    }
    return l;
  }

  Labels labels_;
  std::vector<std::int32_t> parent_, remap_;
  std::vector<std::int32_t> area_;
  int count_ = 0;
};

/// Clears, in place, every component of `mask` with fewer than `min_area` pixels (MATLAB's
/// `bwareaopen(BW, P)`, 8-connected by default). Returns the number of components kept.
inline int remove_small_regions(Mask& mask, int min_area, Components& workspace,
                                Connectivity connectivity = Connectivity::eight) {
  const int n = workspace.compute(mask, connectivity);
  int kept = 0;
  for (int id = 1; id <= n; ++id) kept += workspace.area(id) >= min_area ? 1 : 0;
  if (kept == n) return kept;
  const Labels& lab = workspace.labels();
  for (Eigen::Index i = 0; i < mask.size(); ++i) {
    const std::int32_t id = lab.data()[i];
    if (id != 0 && workspace.area(id) < min_area) mask.data()[i] = 0;
  }
  return kept;
}

/// Allocating convenience for `remove_small_regions`.
inline int remove_small_regions(Mask& mask, int min_area,
                                Connectivity connectivity = Connectivity::eight) {
  Components ws(mask.rows(), mask.cols());
  return remove_small_regions(mask, min_area, ws, connectivity);
}

}  // namespace taxel::image
