// SPDX-License-Identifier: MIT
// Connected components of a mask (4- or 8-connected) and removal of small regions (MATLAB's
// bwareaopen).
#pragma once

#include <algorithm>
#include <bit>
#include <cstdint>
#include <span>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/image/types.hpp"

namespace taxel::image {

/// Connected-component labelling workspace. Labels are assigned in raster order (row by row)
/// from 1; MATLAB numbers in column order, so compare region properties, not label numbers.
/// Reusing one object for images of the same size allocates nothing.
/// Not thread-safe (a reused workspace); one per thread.
class Components {
 public:
  Components() = default;
  /// Preallocates for `rows x cols` images.
  Components(Eigen::Index rows, Eigen::Index cols) { reserve(rows, cols); }

  /// Preallocates for `rows x cols` images.
  template <class = void>
  void reserve(Eigen::Index rows, Eigen::Index cols) {
    detail::checked_pixels("Components", rows, cols);
    labels_.resize(rows, cols);
    parent_.reserve(max_labels(rows, cols));
    remap_.reserve(max_labels(rows, cols));
    area_.reserve(max_labels(rows, cols));
    tally_.reserve(4 * max_labels(rows, cols));
    runs_.reserve(max_labels(rows, cols));
  }

  /// Labels the non-zero pixels of `mask`; returns the number of components.
  /// Two raster passes with union-find over provisional labels. The first pass decides from
  /// the fewest neighbours possible (a set pixel above is adjacent to every other scanned
  /// neighbour under 8-connectivity); every set's root is its smallest provisional label,
  /// which is the label of the component's first pixel in raster order.
  template <class D = void>
  int compute(const Deferred<MaskView, D>& mask, Connectivity connectivity = Connectivity::eight) {
    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    runs_.clear();
    if (cols <= 64) return compute_runs(mask, connectivity);
    labels_.resize(rows, cols);
    parent_.resize(max_labels(rows, cols));
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
    const std::int32_t* remap = flatten(next);
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

  /// Clears from `mask`, which must be the mask of the last `compute`, every component with
  /// fewer than `min_area` pixels. Returns the number of components kept.
  template <class = void>
  int clear_small(Mask& mask, int min_area) const {
    int kept = 0;
    for (int id = 1; id <= count_; ++id) kept += area_[static_cast<std::size_t>(id)] >= min_area;
    if (kept == count_) return kept;
    std::uint8_t* m = mask.data();
    if (!runs_.empty()) {
      const auto cols = static_cast<std::ptrdiff_t>(mask.cols());
      for (const Run& run : runs_) {
        if (area_[static_cast<std::size_t>(run.label)] >= min_area) continue;
        std::uint8_t* row = m + run.row * cols;
        std::fill(row + run.begin, row + run.end + 1, std::uint8_t{0});
      }
      return kept;
    }
    const std::int32_t* lab = labels_.data();
    const std::int32_t* area = area_.data();
    const Eigen::Index total = mask.size();
    for (Eigen::Index i = 0; i < total; ++i) {  // branch-free: region edges are unpredictable
      m[i] &= static_cast<std::uint8_t>(0u - static_cast<unsigned>(area[lab[i]] >= min_area));
    }
    return kept;
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
  // Provisional labels (plus the background): a new label starts a run or a pixel with no
  // labelled neighbour to its left, so a row holds at most (cols + 1) / 2 of them.
  static std::size_t max_labels(Eigen::Index rows, Eigen::Index cols) noexcept {
    return static_cast<std::size_t>(rows * ((cols + 1) / 2)) + 2;
  }

  // A horizontal run of set pixels: columns begin..end (inclusive) of a row.
  struct Run {
    std::int32_t row, begin, end, label;
  };

  // Masks up to 64 columns: rows as bit words, labels per run. A run joins the runs of the row
  // above that overlap it (widened by one column each side under 8-connectivity); labels are
  // written once, run by run, and areas are run lengths.
  template <class D = void>
  int compute_runs(const Deferred<MaskView, D>& mask, Connectivity connectivity) {
    const Eigen::Index rows = mask.rows();
    const Eigen::Index cols = mask.cols();
    const int widen = connectivity == Connectivity::eight ? 1 : 0;
    parent_.resize(max_labels(rows, cols));
    std::int32_t* parent = parent_.data();
    parent[0] = 0;
    std::int32_t next = 1;
    std::size_t prev_begin = 0, prev_end = 0;
    for (Eigen::Index r = 0; r < rows; ++r) {
      std::uint64_t bits = detail::pack_row(mask.data() + r * mask.outerStride(), cols);
      const std::size_t cur_begin = runs_.size();
      std::size_t j = prev_begin;
      while (bits != 0) {
        const int a = std::countr_zero(bits);
        const int len = std::countr_one(bits >> a);
        const int b = a + len - 1;
        bits = b >= 63 ? 0 : bits & (~std::uint64_t{0} << (b + 1));
        while (j < prev_end && runs_[j].end < a - widen) ++j;
        std::int32_t label = 0;
        for (std::size_t k = j; k < prev_end && runs_[k].begin <= b + widen; ++k) {
          if (label == 0) {
            label = runs_[k].label;
          } else {
            unite(label, runs_[k].label);
          }
        }
        if (label == 0) {
          parent[next] = next;
          label = next++;
        }
        runs_.push_back({static_cast<std::int32_t>(r), a, b, label});
      }
      prev_begin = cur_begin;
      prev_end = runs_.size();
    }
    const std::int32_t* remap = flatten(next);
    area_.assign(static_cast<std::size_t>(count_) + 1, 0);
    labels_.resize(rows, cols);
    labels_.setZero();
    std::int32_t* lab = labels_.data();
    for (Run& run : runs_) {
      run.label = remap[run.label];
      std::int32_t* row = lab + static_cast<std::ptrdiff_t>(run.row) * cols;
      std::fill(row + run.begin, row + run.end + 1, run.label);
      area_[static_cast<std::size_t>(run.label)] += run.end - run.begin + 1;
    }
    return count_;
  }

  // Final ids of provisional labels 1..next-1 (0 stays 0), counted into count_: a root takes
  // the next id in raster order; a child its parent's, already final because parent < child.
  const std::int32_t* flatten(std::int32_t next) {
    remap_.resize(static_cast<std::size_t>(next));
    std::int32_t* remap = remap_.data();
    const std::int32_t* parent = parent_.data();
    remap[0] = 0;
    count_ = 0;
    for (std::int32_t l = 1; l < next; ++l) {
      remap[l] = parent[l] == l ? ++count_ : remap[parent[l]];
    }
    return remap;
  }

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
  std::vector<Run> runs_;
  int count_ = 0;
};

/// Clears, in place, every component of `mask` with fewer than `min_area` pixels (MATLAB's
/// `bwareaopen(BW, P)`, 8-connected by default). Returns the number of components kept.
template <class = void>
inline int remove_small_regions(Mask& mask, int min_area, Components& workspace,
                                Connectivity connectivity = Connectivity::eight) {
  workspace.compute(mask, connectivity);
  return workspace.clear_small(mask, min_area);
}

/// Allocating convenience for `remove_small_regions`.
template <class = void>
inline int remove_small_regions(Mask& mask, int min_area,
                                Connectivity connectivity = Connectivity::eight) {
  Components ws(mask.rows(), mask.cols());
  return remove_small_regions(mask, min_area, ws, connectivity);
}

}  // namespace taxel::image
