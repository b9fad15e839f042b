// SPDX-License-Identifier: MIT
// Pressure segmentation (second paper, steps 1-2): 1-D k-means of the pixel values into
// background / low / high pressure, and the high-pressure regions (HPRs) after small-region
// removal.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/status.hpp"
#include "taxel/image/components.hpp"
#include "taxel/image/kmeans.hpp"
#include "taxel/image/types.hpp"

namespace taxel::image {

/// Options of `Segmenter`.
struct SegmentationConfig {
  int k = 3;                                        ///< clusters (the paper: 3), 2..255
  Polarity polarity = Polarity::high_is_pressure;   ///< which end of the scale is pressure
  int min_area = 50;                                ///< HPR components below this are noise (px)
  Connectivity connectivity = Connectivity::eight;  ///< adjacency of HPR components
  /// Integer-valued images in [0, histogram_levels) are clustered from a histogram (exact and
  /// faster); others by sorting. 0 disables the histogram path.
  int histogram_levels = 65536;
};

/// The segmentation of one image.
/// `classes(r, c)` is the pressure class of a pixel: 0 = background (least pressure) up to
/// k-1 = high pressure, after polarity. With fewer distinct values than k, the classes present
/// are 0..kmeans.k-1 mapped to the lowest classes when there is one cluster (all background)
/// and to background plus high pressure otherwise; see `Segmenter::run`.
struct Segmentation : Outcome {
  Image<std::uint8_t> classes;    ///< pressure class per pixel
  ImageD quantised;               ///< each pixel replaced by its cluster's centroid (Fig. 3b)
  Mask high;                      ///< HPR pixels after removal of small regions
  Mask high_raw;                  ///< HPR pixels before removal
  KMeans1dResult kmeans;          ///< the clustering of the pixel values
  int classes_count = 3;          ///< k: classes run 0..k-1, k-1 = high pressure
  int regions = 0;                ///< number of HPR components kept
  double background_level = 0.0;  ///< centroid of the background cluster (I0)
  double high_level = 0.0;        ///< centroid of the high-pressure cluster (I2)
  double pixel_min = 0.0;         ///< smallest pixel value of the image
  double pixel_max = 0.0;         ///< largest pixel value of the image
  double pixel_mean = 0.0;        ///< mean pixel value of the image
};

/// Segmentation workspace; reusing it for images of one size allocates nothing.
/// Not thread-safe (a reused workspace); one per thread.
class Segmenter {
 public:
  /// Throws std::invalid_argument on a bad configuration, naming the field.
  explicit Segmenter(SegmentationConfig cfg = {}, Eigen::Index rows = 32, Eigen::Index cols = 32)
      : cfg_(cfg),
        kmeans_(cfg.k, static_cast<std::size_t>(detail::checked_pixels("Segmenter", rows, cols))),
        components_(rows, cols) {
    if (cfg.k < 2 || cfg.k > 255) {
      throw std::invalid_argument("SegmentationConfig::k = " + std::to_string(cfg.k) +
                                  " is outside the allowed range [2, 255]");
    }
    if (cfg.min_area < 0) {
      throw std::invalid_argument("SegmentationConfig::min_area = " + std::to_string(cfg.min_area) +
                                  " must be >= 0");
    }
    if (cfg.histogram_levels < 0 || cfg.histogram_levels > (1 << 24)) {
      throw std::invalid_argument("SegmentationConfig::histogram_levels must be in [0, 2^24]");
    }
    seg_.classes.resize(rows, cols);
    seg_.quantised.resize(rows, cols);
    seg_.high.resize(rows, cols);
    seg_.high_raw.resize(rows, cols);
    values_.reserve(static_cast<std::size_t>(rows * cols));
    histogram_.reserve(std::min<std::size_t>(static_cast<std::size_t>(cfg.histogram_levels),
                                             static_cast<std::size_t>(rows * cols) * 4 + 256));
    level_class_.reserve(histogram_.capacity());
    level_value_.reserve(histogram_.capacity());
    levels_.reserve(static_cast<std::size_t>(rows * cols));
    split_.reserve(4 * std::min(kSplitHistogramLevels, histogram_.capacity()));
    bounds_.reserve(static_cast<std::size_t>(cfg.k));
  }

  /// The configuration.
  [[nodiscard]] const SegmentationConfig& config() const noexcept { return cfg_; }

  /// Largest pixel magnitude accepted: squares of gradients and sums of squares stay finite.
  static constexpr double kMaxPixelMagnitude = 1e100;

  /// Segments `img`. A non-finite pixel, one beyond +-kMaxPixelMagnitude, or an empty image
  /// gives `invalid_input` with every
  /// output cleared to background. An image with one distinct value is all background (no
  /// HPR); with two, the upper value is high pressure and there is no low-pressure class.
  template <class = void>
  const Segmentation& run(const ImageView& img) {
    const Eigen::Index rows = img.rows();
    const Eigen::Index cols = img.cols();
    seg_.classes.resize(rows, cols);
    seg_.quantised.resize(rows, cols);
    seg_.high.resize(rows, cols);
    seg_.high_raw.resize(rows, cols);
    seg_.regions = 0;
    seg_.classes_count = cfg_.k;
    seg_.background_level = 0.0;
    seg_.high_level = 0.0;
    seg_.status = Status::ok;
    seg_.message.clear();
    if (img.size() == 0) return fail("the image is empty");

    // Pressure values: negate for dark-is-pressure so that clusters ascend in pressure.
    const double sign = cfg_.polarity == Polarity::high_is_pressure ? 1.0 : -1.0;
    // One branch-free pass: range, sum, and whether every pixel is a finite integer within
    // +-2^31 (1.5 * 2^52 added and subtracted rounds to an integer; NaN fails every test).
    // Four lanes of accumulators, so that no floating-point chain waits on its last add.
    const Eigen::Index stride = img.outerStride();
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo4[4] = {kInf, kInf, kInf, kInf};
    double hi4[4] = {-kInf, -kInf, -kInf, -kInf};
    double sum4[4] = {0, 0, 0, 0};
    bool in_range = true;
    bool integral = cfg_.histogram_levels > 0;
    for (Eigen::Index r = 0; r < rows; ++r) {
      const double* row = img.data() + r * stride;
      bool row_ok = true;
      bool row_int = true;
      auto visit = [&](int lane, double v) {
        row_ok &= std::abs(v) <= kMaxPixelMagnitude;
        constexpr double kRound = 6755399441055744.0;  // 1.5 * 2^52
        row_int &= std::abs(v) < 2147483648.0 && (v + kRound) - kRound == v;
        lo4[lane] = v < lo4[lane] ? v : lo4[lane];
        hi4[lane] = v > hi4[lane] ? v : hi4[lane];
        sum4[lane] += v;
      };
      Eigen::Index c = 0;
      for (; c + 4 <= cols; c += 4) {
        visit(0, row[c]);
        visit(1, row[c + 1]);
        visit(2, row[c + 2]);
        visit(3, row[c + 3]);
      }
      for (; c < cols; ++c) visit(0, row[c]);
      in_range = in_range && row_ok;
      integral = integral && row_int;
    }
    const double lo = std::min(std::min(lo4[0], lo4[1]), std::min(lo4[2], lo4[3]));
    const double hi = std::max(std::max(hi4[0], hi4[1]), std::max(hi4[2], hi4[3]));
    const double sum = (sum4[0] + sum4[1]) + (sum4[2] + sum4[3]);
    if (!in_range) {
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c < cols; ++c) {
          const double v = img(r, c);
          if (!std::isfinite(v) || std::abs(v) > kMaxPixelMagnitude) {
            return fail("pixel (" + std::to_string(r) + ", " + std::to_string(c) + ") is " +
                        (std::isfinite(v) ? "beyond +-1e100" : "not finite"));
          }
        }
      }
    }
    seg_.pixel_min = lo;
    seg_.pixel_max = hi;
    seg_.pixel_mean = sum / static_cast<double>(rows * cols);
    integral = integral && hi - lo < static_cast<double>(cfg_.histogram_levels);
    const int top = cfg_.k - 1;
    std::uint8_t* classes = seg_.classes.data();
    double* quantised = seg_.quantised.data();
    std::uint8_t* high_raw = seg_.high_raw.data();
    if (integral) {
      // Histogram over [lo, hi] in pressure order; the levels are kept for the class pass.
      const std::size_t n = static_cast<std::size_t>(hi - lo) + 1;
      histogram_.assign(n, 0);
      levels_.resize(static_cast<std::size_t>(rows * cols));
      std::uint32_t* hist = histogram_.data();
      std::int32_t* level = levels_.data();
      const auto ilo = static_cast<std::int32_t>(lo);
      for (Eigen::Index r = 0; r < rows; ++r) {
        const double* row = img.data() + r * stride;
        for (Eigen::Index c = 0; c < cols; ++c) {
          *level++ = static_cast<std::int32_t>(row[c]) - ilo;
        }
      }
      level = levels_.data();
      const Eigen::Index count = rows * cols;
      if (n <= kSplitHistogramLevels) {
        // Four interleaved histograms: runs of one value (the background) would otherwise
        // chain every increment on the one before through memory.
        split_.assign(4 * n, 0);
        std::uint32_t* h = split_.data();
        Eigen::Index i = 0;
        for (; i + 4 <= count; i += 4) {
          ++h[level[i]];
          ++h[n + static_cast<std::size_t>(level[i + 1])];
          ++h[2 * n + static_cast<std::size_t>(level[i + 2])];
          ++h[3 * n + static_cast<std::size_t>(level[i + 3])];
        }
        for (; i < count; ++i) ++h[level[i]];
        for (std::size_t j = 0; j < n; ++j) {
          const std::uint32_t total = h[j] + h[n + j] + h[2 * n + j] + h[3 * n + j];
          hist[sign > 0 ? j : n - 1 - j] = total;
        }
      } else if (sign > 0) {
        for (Eigen::Index i = 0; i < count; ++i) ++hist[level[i]];
      } else {
        for (Eigen::Index i = 0; i < count; ++i) ++hist[n - 1 - level[i]];
      }
      kmeans_.fit_histogram(histogram_, sign > 0 ? lo : -hi);
    } else {
      values_.resize(static_cast<std::size_t>(rows * cols));
      double* out = values_.data();
      for (Eigen::Index r = 0; r < rows; ++r) {
        const double* row = img.data() + r * stride;
        for (Eigen::Index c = 0; c < cols; ++c) *out++ = sign * row[c];
      }
      kmeans_.fit(values_);
    }
    seg_.kmeans = kmeans_.result();
    const KMeans1dResult& km = kmeans_.result();
    // Map cluster ranks to classes: lowest -> 0, highest -> k-1, middle ones in between.
    auto class_of_cluster = [&](int cl) { return km.k == 1 ? 0 : (cl == km.k - 1 ? top : cl); };
    if (integral) {
      // One lookup per level instead of a search per pixel.
      const std::size_t n = histogram_.size();
      level_class_.resize(n);
      level_value_.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const int cl = km.cluster_of(sign * (lo + static_cast<double>(i)));
        level_class_[i] = static_cast<std::uint8_t>(class_of_cluster(cl));
        level_value_[i] = sign * km.centroids[static_cast<std::size_t>(cl)];
      }
      const std::uint8_t* lc = level_class_.data();
      const double* lv = level_value_.data();
      const std::int32_t* level = levels_.data();
      const auto utop = static_cast<std::uint8_t>(top);
      for (Eigen::Index i = 0; i < rows * cols; ++i) {
        const std::uint8_t cls = lc[level[i]];
        classes[i] = cls;
        quantised[i] = lv[level[i]];
        high_raw[i] = cls == utop ? 1 : 0;
      }
    } else {
      // cluster_of without branches: the number of cluster boundaries below the value.
      bounds_.clear();
      for (int c = 0; c + 1 < km.k; ++c) {
        const auto i = static_cast<std::size_t>(c);
        bounds_.push_back(0.5 * (km.upper[i] + km.lower[i + 1]));
      }
      const double* bounds = bounds_.data();
      const std::size_t nb = bounds_.size();
      for (Eigen::Index r = 0; r < rows; ++r) {
        const double* row = img.data() + r * stride;
        for (Eigen::Index c = 0; c < cols; ++c) {
          const double v = sign * row[c];
          int cl = 0;
          for (std::size_t b = 0; b < nb; ++b) cl += v > bounds[b] ? 1 : 0;
          const int cls = class_of_cluster(cl);
          const Eigen::Index i = r * cols + c;
          classes[i] = static_cast<std::uint8_t>(cls);
          quantised[i] = sign * km.centroids[static_cast<std::size_t>(cl)];
          high_raw[i] = static_cast<std::uint8_t>(cls == top ? 1 : 0);
        }
      }
    }
    seg_.background_level = sign * km.centroids.front();
    seg_.high_level = km.k > 1 ? sign * km.centroids.back() : seg_.background_level;
    seg_.high = seg_.high_raw;
    seg_.regions = remove_small_regions(seg_.high, cfg_.min_area, components_, cfg_.connectivity);
    if (km.k < cfg_.k) seg_.message = km.message;
    return seg_;
  }

  /// The last segmentation.
  [[nodiscard]] const Segmentation& result() const noexcept { return seg_; }

  /// The connected components of the last image's HPRs before small-region removal
  /// (`high_raw`): the kept regions are those with area >= min_area.
  [[nodiscard]] const Components& components() const noexcept { return components_; }

 private:
  const Segmentation& fail(std::string why) {
    seg_.classes.setZero();
    seg_.quantised.setZero();
    seg_.high.setZero();
    seg_.high_raw.setZero();
    seg_.pixel_min = seg_.pixel_max = seg_.pixel_mean = 0.0;
    seg_.status = Status::invalid_input;
    seg_.message = std::move(why);
    seg_.kmeans = KMeans1dResult{};
    return seg_;
  }

  SegmentationConfig cfg_;
  KMeans1d kmeans_;
  Components components_;
  Segmentation seg_;
  std::vector<double> values_;
  std::vector<std::uint32_t> histogram_;
  std::vector<std::uint8_t> level_class_;
  std::vector<double> level_value_;
  std::vector<std::int32_t> levels_;
  std::vector<std::uint32_t> split_;
  std::vector<double> bounds_;
  static constexpr std::size_t kSplitHistogramLevels = 4096;
};

/// Allocating convenience: segments one image.
template <class = void>
inline Segmentation segment(const ImageView& img, const SegmentationConfig& cfg = {}) {
  Segmenter s(cfg, img.rows(), img.cols());
  return s.run(img);
}

}  // namespace taxel::image
