// SPDX-License-Identifier: MIT
// Connected components of a mask (4- or 8-connected) and removal of small regions (MATLAB's
// bwareaopen).
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
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
    parent_.reserve(static_cast<std::size_t>(rows * cols) / 2 + 2);
    remap_.reserve(static_cast<std::size_t>(rows * cols) / 2 + 2);
    area_.reserve(static_cast<std::size_t>(rows * cols) / 2 + 2);
    tally_.reserve(4 * (static_cast<std::size_t>(rows * cols) / 2 + 2));
  }

  /// Labels the non-zero pixels of `mask`; returns the number of components.
  /// Two raster passes with union-find over provisional labels. The first pass decides from
  /// the fewest neighbours possible (a set pixel above is adjacent to every other scanned
  /// neighbour under 8-connectivity); every set's root is its smallest provisional label,
  /// which is the label of the component's first pixel in raster order.
  int compute(const MaskView& mask, Connectivity connectivity = Connectivity::eight) {
    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    labels_.resize(rows, cols);
    parent_.resize(static_cast<std::size_t>(rows * cols) / 2 + 2);
    std::int32_t* parent = parent_.data();
    std::int32_t next = 1;
    parent[0] = 0;
    auto fresh = [&]() {
      parent[next] = next;
      return next++;
    };
    const bool eight = connectivity == Connectivity::eight;
    for (Eigen::Index r = 0; r < rows; ++r) {
      const std::uint8_t* m = mask.data() + r * mask.outerStride();
      std::int32_t* lab = labels_.data() + r * cols;
      if (r == 0) {
        for (Eigen::Index c = 0; c < cols; ++c) {
          if (m[c] == 0) {
            lab[c] = 0;
          } else {
            lab[c] = c > 0 && lab[c - 1] != 0 ? lab[c - 1] : fresh();
          }
        }
        continue;
      }
      const std::int32_t* up = lab - cols;
      for (Eigen::Index c = 0; c < cols; ++c) {
        if (m[c] == 0) {
          lab[c] = 0;
          continue;
        }
        const std::int32_t left = c > 0 ? lab[c - 1] : 0;
        if (up[c] != 0) {
          lab[c] = up[c];
          if (!eight && left != 0 && left != up[c]) unite(up[c], left);
          continue;
        }
        if (!eight) {
          lab[c] = left != 0 ? left : fresh();
          continue;
        }
        const std::int32_t ul = c > 0 ? up[c - 1] : 0;
        const std::int32_t ur = c + 1 < cols ? up[c + 1] : 0;
        const std::int32_t w = ul != 0 ? ul : left;  // ul and left touch: one set
        if (w != 0) {
          lab[c] = w;
          if (ur != 0 && ur != w) unite(w, ur);
        } else {
          lab[c] = ur != 0 ? ur : fresh();
        }
      }
    }
    // Flatten: a root keeps the next final id in raster order; a child takes its parent's,
    // already final because parent < child.
    remap_.resize(static_cast<std::size_t>(next));
    std::int32_t* remap = remap_.data();
    remap[0] = 0;
    count_ = 0;
    for (std::int32_t l = 1; l < next; ++l) {
      remap[l] = parent[l] == l ? ++count_ : remap[parent[l]];
    }
    // Areas in four interleaved tallies: a run of one label (above all the background) would
    // otherwise chain every increment on the one before through memory.
    const auto stride = static_cast<std::size_t>(count_) + 1;
    tally_.assign(4 * stride, 0);
    std::int32_t* t = tally_.data();
    std::int32_t* lab = labels_.data();
    const Eigen::Index total = rows * cols;
    Eigen::Index i = 0;
    for (; i + 4 <= total; i += 4) {
      const std::int32_t l0 = remap[lab[i]], l1 = remap[lab[i + 1]];
      const std::int32_t l2 = remap[lab[i + 2]], l3 = remap[lab[i + 3]];
      lab[i] = l0;
      lab[i + 1] = l1;
      lab[i + 2] = l2;
      lab[i + 3] = l3;
      ++t[l0];
      ++t[stride + static_cast<std::size_t>(l1)];
      ++t[2 * stride + static_cast<std::size_t>(l2)];
      ++t[3 * stride + static_cast<std::size_t>(l3)];
    }
    for (; i < total; ++i) {
      lab[i] = remap[lab[i]];
      ++t[lab[i]];
    }
    area_.resize(stride);
    area_[0] = 0;
    for (std::size_t l = 1; l < stride; ++l) {
      area_[l] = t[l] + t[stride + l] + t[2 * stride + l] + t[3 * stride + l];
    }
    return count_;
  }

  /// Number of components of the last `compute`.
  [[nodiscard]] int count() const noexcept { return count_; }
  /// Label image of the last `compute` (0 = background).
  [[nodiscard]] const Labels& labels() const noexcept { return labels_; }
  /// Pixel counts indexed by component id (entry 0, the background, is 0).
  [[nodiscard]] std::span<const std::int32_t> areas() const noexcept { return area_; }
  /// Pixel count of component `id` (1-based).
  [[nodiscard]] std::int32_t area(int id) const noexcept {
    return area_[static_cast<std::size_t>(id)];
  }

 private:
  std::int32_t find(std::int32_t l) noexcept {
    std::int32_t* parent = parent_.data();
    while (parent[l] != l) {
      parent[l] = parent[parent[l]];
      l = parent[l];
    }
    return l;
  }

  // Joins the sets of a and b; the smaller root becomes the root.
  void unite(std::int32_t a, std::int32_t b) noexcept {
    a = find(a);
    b = find(b);
    if (a < b) {
      parent_[static_cast<std::size_t>(b)] = a;
    } else if (b < a) {
      parent_[static_cast<std::size_t>(a)] = b;
    }
  }

  Labels labels_;
  std::vector<std::int32_t> parent_, remap_;
  std::vector<std::int32_t> area_, tally_;
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
  const std::int32_t* lab = workspace.labels().data();
  const std::int32_t* area = workspace.areas().data();
  std::uint8_t* m = mask.data();
  const Eigen::Index total = mask.size();
  for (Eigen::Index i = 0; i < total; ++i) {  // branch-free: region edges are unpredictable
    m[i] &= static_cast<std::uint8_t>(0u - static_cast<unsigned>(area[lab[i]] >= min_area));
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
