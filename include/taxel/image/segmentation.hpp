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
};

/// Segmentation workspace; reusing it for images of one size allocates nothing.
class Segmenter {
 public:
  /// Throws std::invalid_argument on a bad configuration, naming the field.
  explicit Segmenter(SegmentationConfig cfg = {}, Eigen::Index rows = 32, Eigen::Index cols = 32)
      : cfg_(cfg), kmeans_(cfg.k, static_cast<std::size_t>(rows * cols)), components_(rows, cols) {
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
  }

  /// The configuration.
  [[nodiscard]] const SegmentationConfig& config() const noexcept { return cfg_; }

  /// Largest pixel magnitude accepted: squares of gradients and sums of squares stay finite.
  static constexpr double kMaxPixelMagnitude = 1e100;

  /// Segments `img`. A non-finite pixel, one beyond +-kMaxPixelMagnitude, or an empty image
  /// gives `invalid_input` with every
  /// output cleared to background. An image with one distinct value is all background (no
  /// HPR); with two, the upper value is high pressure and there is no low-pressure class.
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
    bool integral = cfg_.histogram_levels > 0;
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (Eigen::Index r = 0; r < rows; ++r) {
      for (Eigen::Index c = 0; c < cols; ++c) {
        const double v = img(r, c);
        if (!std::isfinite(v) || std::abs(v) > kMaxPixelMagnitude) {
          return fail("pixel (" + std::to_string(r) + ", " + std::to_string(c) + ") is " +
                      (std::isfinite(v) ? "beyond +-1e100" : "not finite"));
        }
        lo = std::min(lo, v);
        hi = std::max(hi, v);
        // Integer-valued? (a truncating conversion, cheaper than std::floor without SSE4.1)
        integral = integral && v > -2147483648.0 && v < 2147483647.0 &&
                   static_cast<double>(static_cast<std::int32_t>(v)) == v;
      }
    }
    integral = integral && hi - lo < static_cast<double>(cfg_.histogram_levels);
    if (integral) {
      // Histogram over [lo, hi] in pressure order.
      const std::size_t n = static_cast<std::size_t>(hi - lo) + 1;
      histogram_.assign(n, 0);
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c < cols; ++c) {
          const auto level = static_cast<std::size_t>(img(r, c) - lo);
          ++histogram_[sign > 0 ? level : n - 1 - level];
        }
      }
      kmeans_.fit_histogram(histogram_, sign > 0 ? lo : -hi);
    } else {
      values_.clear();
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c < cols; ++c) values_.push_back(sign * img(r, c));
      }
      kmeans_.fit(values_);
    }
    seg_.kmeans = kmeans_.result();
    const KMeans1dResult& km = kmeans_.result();
    // Map cluster ranks to classes: lowest -> 0, highest -> k-1, middle ones in between.
    const int top = cfg_.k - 1;
    auto class_of_cluster = [&](int cl) { return km.k == 1 ? 0 : (cl == km.k - 1 ? top : cl); };
    if (integral) {
      // One lookup per level instead of a search per pixel.
      const std::size_t n = histogram_.size();
      level_class_.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        level_class_[i] =
            static_cast<std::uint8_t>(km.cluster_of(sign * (lo + static_cast<double>(i))));
      }
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c < cols; ++c) {
          const int cl = level_class_[static_cast<std::size_t>(img(r, c) - lo)];
          const int cls = class_of_cluster(cl);
          seg_.classes(r, c) = static_cast<std::uint8_t>(cls);
          seg_.quantised(r, c) = sign * km.centroids[static_cast<std::size_t>(cl)];
          seg_.high_raw(r, c) = static_cast<std::uint8_t>(cls == top ? 1 : 0);
        }
      }
    } else {
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c < cols; ++c) {
          const int cl = km.cluster_of(sign * img(r, c));
          const int cls = class_of_cluster(cl);
          seg_.classes(r, c) = static_cast<std::uint8_t>(cls);
          seg_.quantised(r, c) = sign * km.centroids[static_cast<std::size_t>(cl)];
          seg_.high_raw(r, c) = static_cast<std::uint8_t>(cls == top ? 1 : 0);
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
};

/// Allocating convenience: segments one image.
inline Segmentation segment(const ImageView& img, const SegmentationConfig& cfg = {}) {
  Segmenter s(cfg, img.rows(), img.cols());
  return s.run(img);
}

}  // namespace taxel::image
