// SPDX-License-Identifier: MIT
// Connected components of a mask (4- or 8-connected) and removal of small regions (MATLAB's
// bwareaopen).
#pragma once

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
    stack_.reserve(static_cast<std::size_t>(rows * cols));
    area_.reserve(static_cast<std::size_t>(rows * cols) + 1);
  }

  /// Labels the non-zero pixels of `mask`; returns the number of components.
  int compute(const MaskView& mask, Connectivity connectivity = Connectivity::eight) {
    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    labels_.resize(rows, cols);
    labels_.setZero();
    area_.assign(1, 0);
    count_ = 0;
    const bool eight = connectivity == Connectivity::eight;
    for (Eigen::Index r0 = 0; r0 < rows; ++r0) {
      for (Eigen::Index c0 = 0; c0 < cols; ++c0) {
        if (mask(r0, c0) == 0 || labels_(r0, c0) != 0) continue;
        const std::int32_t id = ++count_;
        std::int32_t area = 0;
        stack_.clear();
        stack_.push_back(static_cast<std::int32_t>(r0 * cols + c0));
        labels_(r0, c0) = id;
        while (!stack_.empty()) {
          const std::int32_t p = stack_.back();
          stack_.pop_back();
          ++area;
          const Eigen::Index r = p / cols;
          const Eigen::Index c = p % cols;
          for (Eigen::Index dr = -1; dr <= 1; ++dr) {
            for (Eigen::Index dc = -1; dc <= 1; ++dc) {
              if ((dr == 0 && dc == 0) || (!eight && dr != 0 && dc != 0)) continue;
              const Eigen::Index rr = r + dr;
              const Eigen::Index cc = c + dc;
              if (rr < 0 || rr >= rows || cc < 0 || cc >= cols) continue;
              if (mask(rr, cc) == 0 || labels_(rr, cc) != 0) continue;
              labels_(rr, cc) = id;
              stack_.push_back(static_cast<std::int32_t>(rr * cols + cc));
            }
          }
        }
        area_.push_back(area);
      }
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
  Labels labels_;
  std::vector<std::int32_t> stack_;
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
