// SPDX-License-Identifier: MIT
// 3-D shape from one pressure image (second paper, step 6): RecEdged, a row-scan state machine
// for objects with edges, and RecEdgeless, background cropping + finger-gap healing + column-wise
// polynomial fit for planar and cylindrical objects. Both return an M x N height map. The paper
// lost the figures that held both algorithms; every open choice (the edge condition, whether a
// step lifts the whole row, the step constant K, the polynomial degree, the gap-healing rule) is
// an option here, with defaults chosen to give a raised plateau for two-edged objects.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/deferred.hpp"
#include "taxel/image/segmentation.hpp"
#include "taxel/image/types.hpp"

namespace taxel::image {

/// Smoothing applied after RecEdged ("postprocessing", not described in the paper).
enum class PostProcess { none, mean3x3, median3x3 };

/// Options of RecEdged.
struct RecEdgedConfig {
  /// Step height factor: T1 = T2 = k * I2 (paper: unknown), in [-1e6, 1e6].
  double k = 0.5;
  double background_fraction = 0.5;  ///< rows with more background than this are skipped
  /// false (the text): the surface rises when a row has more low- than high-pressure pixels;
  /// true: when it has more high- than low-pressure pixels (the physical reading).
  bool swap_edge_condition = false;
  bool fill_whole_row = false;                  ///< raise the whole row, not only contact pixels
  bool keep_level_on_skipped_rows = false;      ///< skipped rows take the current level, not 0
  PostProcess postprocess = PostProcess::none;  ///< optional 3x3 smoothing of the result

  /// Throws std::invalid_argument naming the bad field.
  void validate() const {
    // (Bounded so that the heights, k times pixel levels of at most 1e100, and their squared
    // gradients stay finite: a k of 1e300 made the hybrid features infinite.)
    if (!(std::abs(k) <= 1e6)) {
      throw std::invalid_argument(
          "RecEdgedConfig::k must be in [-1e6, 1e6] (steps of k times the high-pressure level), "
          "got " +
          std::to_string(k));
    }
    if (!(background_fraction >= 0.0 && background_fraction <= 1.0)) {
      throw std::invalid_argument("RecEdgedConfig::background_fraction must be in [0, 1]");
    }
  }
};

/// How RecEdgeless fills background pixels between contacts within a row (finger gaps).
enum class Healing {
  linear,    ///< linear interpolation between the nearest contact pixels left and right
  row_mean,  ///< the mean of the row's contact pixels
  none,      ///< leave gaps as measured
};

/// Which values RecEdgeless fits.
enum class HeightSource {
  raw,        ///< the pressure image itself (default)
  quantised,  ///< the k-means cluster centroids
};

/// Options of RecEdgeless.
struct RecEdgelessConfig {
  double background_fraction = 0.5;  ///< rows, then columns, with more background are removed
  int degree = 2;                    ///< polynomial degree of the column fit, 0..6 (paper: unknown)
  Healing healing = Healing::linear;  ///< Fill holes of the reconstruction from their neighbours.
  HeightSource source = HeightSource::raw;  ///< The image the surface is fitted to.

  /// Throws std::invalid_argument naming the bad field.
  void validate() const {
    if (!(background_fraction >= 0.0 && background_fraction <= 1.0)) {
      throw std::invalid_argument("RecEdgelessConfig::background_fraction must be in [0, 1]");
    }
    if (degree < 0 || degree > 6) {
      throw std::invalid_argument("RecEdgelessConfig::degree = " + std::to_string(degree) +
                                  " is outside the allowed range [0, 6]");
    }
  }
};

/// Reconstruction workspace; reusing it for images of one size allocates nothing.
/// Not thread-safe (a reused workspace); one per thread.
class Reconstructor {
 public:
  /// A workspace for images of rows x cols. Throws std::invalid_argument for a bad configuration.
  Reconstructor(RecEdgedConfig edged = {}, RecEdgelessConfig edgeless = {}, Eigen::Index rows = 32,
                Eigen::Index cols = 32)
      : edged_(edged), edgeless_(edgeless) {
    edged.validate();
    edgeless.validate();
    detail::checked_pixels("Reconstructor", rows, cols);
    height_.resize(rows, cols);
    scratch_.resize(rows, cols);
    block_.resize(rows, cols);
    gap_.resize(rows, cols);
    vander_.resize(rows, 7);
    hat_.resize(7, rows);
    keep_rows_.reserve(static_cast<std::size_t>(rows));
    keep_cols_.reserve(static_cast<std::size_t>(cols));
  }

  /// RecEdged: scans rows top to bottom over the segmentation's classes (C0 = background,
  /// C2 = high pressure, C1 = the classes between) with a two-state machine. A row with more
  /// background than `background_fraction` of its length is skipped. Otherwise, when not raised
  /// and the edge condition holds, the level rises by T1 = k * I2; when raised and the opposite
  /// condition holds, it falls by T2 = k * I2. Contact pixels (or whole rows) take the level.
  template <class D = void>
  const Deferred<ImageD, D>& rec_edged(const Deferred<Segmentation, D>& seg) {
    const auto& cls = seg.classes;
    const Eigen::Index rows = cls.rows();
    const Eigen::Index cols = cls.cols();
    height_.resize(rows, cols);
    height_.setZero();
    if (!seg.ok() || rows == 0) return height_;
    const int top = seg.classes_count - 1;
    const double step = edged_.k * seg.high_level;
    double level = 0.0;
    bool raised = false;
    for (Eigen::Index r = 0; r < rows; ++r) {
      // Branch-free tallies: class edges within a row are unpredictable.
      const std::uint8_t* row = &cls(r, 0);
      Eigen::Index n0 = 0, n2 = 0;
      for (Eigen::Index c = 0; c < cols; ++c) {
        n0 += row[c] == 0 ? 1 : 0;
        n2 += row[c] >= top ? 1 : 0;
      }
      const Eigen::Index n1 = cols - n0 - n2;
      if (static_cast<double>(n0) > edged_.background_fraction * static_cast<double>(cols)) {
        if (edged_.keep_level_on_skipped_rows) height_.row(r).setConstant(level);
        continue;
      }
      const bool rise = edged_.swap_edge_condition ? n2 > n1 : n1 > n2;
      const bool fall = edged_.swap_edge_condition ? n1 > n2 : n2 > n1;
      if (!raised && rise) {
        level += step;
        raised = true;
      } else if (raised && fall) {
        level -= step;
        raised = false;
      }
      double* out = &height_(r, 0);
      if (edged_.fill_whole_row) {
        for (Eigen::Index c = 0; c < cols; ++c) out[c] = level;
      } else {
        for (Eigen::Index c = 0; c < cols; ++c) out[c] = row[c] != 0 ? level : 0.0;
      }
    }
    if (edged_.postprocess != PostProcess::none) smooth3x3(edged_.postprocess);
    return height_;
  }

  /// RecEdgeless: removes rows, then columns, that are mostly background; heals the gaps
  /// between contact pixels within each remaining row; replaces every remaining column by its
  /// least-squares polynomial of `degree` in the row coordinate normalised to [-1, 1] (the
  /// degree drops to rows - 1 when fewer rows remain); and pastes the block back into a zero
  /// M x N frame at its original rows and columns. All background gives an all-zero map.
  template <class D = void>
  const Deferred<ImageD, D>& rec_edgeless(const Deferred<ImageView, D>& img,
                                          const Deferred<Segmentation, D>& seg) {
    const auto& cls = seg.classes;
    const Eigen::Index rows = cls.rows();
    const Eigen::Index cols = cls.cols();
    height_.resize(rows, cols);
    height_.setZero();
    if (!seg.ok() || rows == 0 || img.rows() != rows || img.cols() != cols) return height_;
    if (block_.rows() != rows || block_.cols() != cols) {  // a new size: allocate once
      block_.resize(rows, cols);
      gap_.resize(rows, cols);
      vander_.resize(rows, 7);
      hat_.resize(7, rows);
    }
    const double frac = edgeless_.background_fraction;
    keep_rows_.clear();
    keep_cols_.clear();
    for (Eigen::Index r = 0; r < rows; ++r) {
      Eigen::Index n0 = 0;
      const std::uint8_t* row = &cls(r, 0);
      for (Eigen::Index c = 0; c < cols; ++c) n0 += row[c] == 0 ? 1 : 0;
      if (static_cast<double>(n0) <= frac * static_cast<double>(cols)) keep_rows_.push_back(r);
    }
    if (keep_rows_.empty()) return height_;
    const auto m1 = static_cast<Eigen::Index>(keep_rows_.size());
    for (Eigen::Index c = 0; c < cols; ++c) {
      Eigen::Index n0 = 0;
      for (const Eigen::Index r : keep_rows_) n0 += cls(r, c) == 0 ? 1 : 0;
      if (static_cast<double>(n0) <= frac * static_cast<double>(m1)) keep_cols_.push_back(c);
    }
    if (keep_cols_.empty()) return height_;
    const auto n1 = static_cast<Eigen::Index>(keep_cols_.size());

    // The cropped block and its background flags.
    const bool quantised = edgeless_.source == HeightSource::quantised;
    for (Eigen::Index i = 0; i < m1; ++i) {
      for (Eigen::Index j = 0; j < n1; ++j) {
        const Eigen::Index r = keep_rows_[static_cast<std::size_t>(i)];
        const Eigen::Index c = keep_cols_[static_cast<std::size_t>(j)];
        block_(i, j) = quantised ? seg.quantised(r, c) : img(r, c);
        gap_(i, j) = cls(r, c) == 0 ? 1 : 0;
      }
    }
    heal(m1, n1);
    fit_columns(m1, n1);
    for (Eigen::Index i = 0; i < m1; ++i) {
      for (Eigen::Index j = 0; j < n1; ++j) {
        height_(keep_rows_[static_cast<std::size_t>(i)], keep_cols_[static_cast<std::size_t>(j)]) =
            block_(i, j);
      }
    }
    return height_;
  }

  /// The last height map.
  [[nodiscard]] const ImageD& height() const noexcept { return height_; }

 private:
  template <class = void>
  void heal(Eigen::Index m1, Eigen::Index n1) {
    if (edgeless_.healing == Healing::none) return;
    for (Eigen::Index i = 0; i < m1; ++i) {
      Eigen::Index first = -1, last = -1;
      double sum = 0;
      Eigen::Index count = 0;
      for (Eigen::Index j = 0; j < n1; ++j) {
        if (gap_(i, j) != 0) continue;
        if (first < 0) first = j;
        last = j;
        sum += block_(i, j);
        ++count;
      }
      if (count == 0) continue;
      const double mean = sum / static_cast<double>(count);
      Eigen::Index left = first;
      for (Eigen::Index j = first + 1; j < last; ++j) {
        if (gap_(i, j) == 0) {
          left = j;
          continue;
        }
        if (edgeless_.healing == Healing::row_mean) {
          block_(i, j) = mean;
          continue;
        }
        Eigen::Index right = j + 1;
        while (gap_(i, right) != 0) ++right;  // terminates: `last` is a contact pixel
        const double t = static_cast<double>(j - left) / static_cast<double>(right - left);
        block_(i, j) = (1 - t) * block_(i, left) + t * block_(i, right);
      }
    }
  }

  template <class = void>
  void fit_columns(Eigen::Index m1, Eigen::Index n1) {
    const int d = static_cast<int>(std::min<Eigen::Index>(edgeless_.degree, m1 - 1));
    // Vandermonde rows v_i = (1, x_i, ..., x_i^d) with x normalised to [-1, 1], kept in
    // `vander_` (m1 x 7); the least-squares coefficients of a column y are G^-1 V' y with
    // G = V'V, so the hat rows H = G^-1 V' (d+1 x m1) are computed once for all columns.
    using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 7, 7>;
    Small gram = Small::Zero(d + 1, d + 1);
    for (Eigen::Index i = 0; i < m1; ++i) {
      const double x =
          m1 == 1 ? 0.0 : -1.0 + 2.0 * static_cast<double>(i) / static_cast<double>(m1 - 1);
      powers(x, d, &vander_(i, 0));
      for (int a = 0; a <= d; ++a) {
        for (int b = 0; b <= d; ++b) gram(a, b) += vander_(i, a) * vander_(i, b);
      }
    }
    const Eigen::LDLT<Small> ldlt(gram);
    Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 7, 1> e(d + 1);
    for (Eigen::Index i = 0; i < m1; ++i) {
      for (int a = 0; a <= d; ++a) e(a) = vander_(i, a);
      const auto h = ldlt.solve(e).eval();
      for (int a = 0; a <= d; ++a) hat_(a, i) = h(a);
    }
    double coef[7];
    for (Eigen::Index j = 0; j < n1; ++j) {
      for (int a = 0; a <= d; ++a) {
        double acc = 0;
        for (Eigen::Index i = 0; i < m1; ++i) acc += hat_(a, i) * block_(i, j);
        coef[a] = acc;
      }
      for (Eigen::Index i = 0; i < m1; ++i) {
        double v = 0;
        for (int a = 0; a <= d; ++a) v += coef[a] * vander_(i, a);
        block_(i, j) = v;
      }
    }
  }

  static void powers(double x, int d, double* out) noexcept {
    out[0] = 1.0;
    for (int a = 1; a <= d; ++a) out[a] = out[a - 1] * x;
  }

  template <class = void>
  void smooth3x3(PostProcess kind) {
    const Eigen::Index rows = height_.rows();
    const Eigen::Index cols = height_.cols();
    scratch_.resize(rows, cols);
    double w[9];
    for (Eigen::Index r = 0; r < rows; ++r) {
      for (Eigen::Index c = 0; c < cols; ++c) {
        int n = 0;
        for (Eigen::Index dr = -1; dr <= 1; ++dr) {
          for (Eigen::Index dc = -1; dc <= 1; ++dc) {
            const Eigen::Index rr = std::clamp<Eigen::Index>(r + dr, 0, rows - 1);
            const Eigen::Index cc = std::clamp<Eigen::Index>(c + dc, 0, cols - 1);
            w[n++] = height_(rr, cc);
          }
        }
        if (kind == PostProcess::mean3x3) {
          double s = 0;
          for (double v : w) s += v;
          scratch_(r, c) = s / 9.0;
        } else {
          std::nth_element(w, w + 4, w + 9);
          scratch_(r, c) = w[4];
        }
      }
    }
    height_.swap(scratch_);
  }

  RecEdgedConfig edged_;
  RecEdgelessConfig edgeless_;
  ImageD height_, scratch_, block_;
  Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor> vander_;
  Eigen::Matrix<double, 7, Eigen::Dynamic> hat_;
  Image<std::uint8_t> gap_;
  std::vector<Eigen::Index> keep_rows_, keep_cols_;
};

}  // namespace taxel::image
