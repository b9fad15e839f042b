// SPDX-License-Identifier: MIT
// The whole per-image chain of the second paper in one workspace: segmentation, HPR
// descriptors, contour gradients, the edged/edgeless decision, RecEdged or RecEdgeless, the
// hybrid feature vector and, optionally, a classifier's decision. No allocation after
// construction for images of the constructed size.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "taxel/core/parallel.hpp"
#include "taxel/core/status.hpp"
#include "taxel/image/components.hpp"
#include "taxel/image/features.hpp"
#include "taxel/image/gradient.hpp"
#include "taxel/image/reconstruction.hpp"
#include "taxel/image/regionprops.hpp"
#include "taxel/image/segmentation.hpp"

namespace taxel::image {

/// Decides edged (true) or edgeless (false) from the 23 edge features.
template <class D>
concept EdgeDecider = requires(const D& d, const Eigen::VectorXd& f) {
  { d.edged(f) } -> std::convertible_to<bool>;
};

/// Classifies a hybrid feature vector into a class label.
template <class C>
concept FeatureClassifier = requires(const C& c, const Eigen::VectorXd& f) {
  { c.predict(f) } -> std::convertible_to<int>;
};

/// The paper's rule: edged when the mean contour gradient magnitude of the largest HPR exceeds
/// a threshold (`Gm > Gth`, Gth = 25 on a 0-255 scale).
struct GradientThreshold {
  double threshold = 25.0;  ///< Gth
  /// True when the edge features say the object has edges (EdgeDecider).
  [[nodiscard]] bool edged(const Eigen::VectorXd& f) const noexcept { return f(17) > threshold; }
};

/// The null classifier: no label (-1). Replace with a trained linear model.
struct NoClassifier {
  /// No label: -1 (FeatureClassifier).
  [[nodiscard]] int predict(const Eigen::VectorXd& /*features*/) const noexcept { return -1; }
};

/// Which image the contour gradients of the edge features are taken on.
enum class GradientSource {
  raw,        ///< the pressure image (default: "sudden vs gradual change" of pressure)
  quantised,  ///< the k-means cluster image
};

/// Options of `Recognizer`.
struct RecognizerConfig {
  SegmentationConfig segmentation{};  ///< k-means segmentation and high-pressure regions.
  GradientSource gradient_source =
      GradientSource::raw;  ///< Which image the contour gradients are taken on.
  RecEdgedConfig edged{};   ///< True when the edge features say the object has edges (EdgeDecider).
  RecEdgelessConfig edgeless{};  ///< RecEdgeless's options.
};

/// Result of one image.
struct Recognition : Outcome {
  bool edged = false;             ///< the edged/edgeless decision
  double contour_gradient = 0.0;  ///< Gm of the largest HPR (feature 18)
  Eigen::VectorXd regional;       ///< 11 regional features
  Eigen::VectorXd edge_features;  ///< 23 edged/edgeless features
  Eigen::VectorXd hybrid;         ///< rows*cols gradient magnitudes (row-major) + 11
  int label = -1;                 ///< the classifier's label (-1 without one)
};

/// Runs the second paper's chain on images of a fixed size.
///
/// Features 15-23: the paper lists three indices for each of "area",
/// "average gradient magnitude" and "average gradient angle" of "the HPR having maximum area";
/// taxel reads them as the three largest HPRs (8-connected, after small-region removal), in
/// descending area, zero-padded when fewer exist. Gradient means are over each region's contour
/// pixels (bwperim, 4-connected).
/// Not thread-safe: `recognize` reuses the workspace it owns; use one Recognizer per thread
/// (copies are independent).
template <EdgeDecider Decider = GradientThreshold, FeatureClassifier Classifier = NoClassifier>
class Recognizer {
 public:
  /// A workspace for images of rows x cols. Throws std::invalid_argument for a bad configuration.
  explicit Recognizer(Eigen::Index rows = 32, Eigen::Index cols = 32, RecognizerConfig cfg = {},
                      Decider decider = {}, Classifier classifier = {})
      : rows_((checked_size(rows, cols), rows)),
        cols_(cols),
        cfg_(cfg),
        decider_(std::move(decider)),
        classifier_(std::move(classifier)),
        segmenter_(cfg.segmentation, rows, cols),
        analyzer_(RegionPropsOptions{.zero_based = false, .convex = true, .perimeter = false}, rows,
                  cols),
        reconstructor_(cfg.edged, cfg.edgeless, rows, cols) {
    result_.regional.setZero(kRegionalFeatures);
    result_.edge_features.setZero(kEdgeFeatures);
    result_.hybrid.setZero(rows * cols + kRegionalFeatures);
    slot_.reserve(static_cast<std::size_t>(rows * cols) / 2 + 2);
    result_.message.reserve(64);
  }

  /// Runs the chain on `img`, which must be rows x cols. A wrong size or a non-finite pixel
  /// gives `invalid_input` with all features zero.
  const Recognition& recognize(const ImageView& img) {
    Recognition& res = result_;
    res.edged = false;
    res.contour_gradient = 0.0;
    res.label = -1;
    res.status = Status::ok;
    res.message.clear();
    auto fail = [&](Status status, const std::string& why) -> const Recognition& {
      res.regional.setZero();
      res.edge_features.setZero();
      res.hybrid.setZero();
      res.status = status;
      res.message = why;
      return res;
    };
    if (img.rows() != rows_ || img.cols() != cols_) {
      return fail(Status::invalid_input, "image size does not match the recognizer's");
    }
    const Segmentation& seg = segmenter_.run(img);
    if (!seg.ok()) return fail(seg.status, seg.message);

    // Regional descriptors of the union of the HPRs.
    const RegionProps& props = analyzer_.compute(seg.high);
    regional_features(props, res.regional);
    res.edge_features.head<kRegionalFeatures>() = res.regional;
    res.edge_features(11) = seg.pixel_max;
    res.edge_features(12) = seg.pixel_min;
    res.edge_features(13) = seg.pixel_mean;

    // The three largest HPRs (components of the segmenter kept by the area rule) and the
    // Sobel gradients on their contour pixels.
    const Components& comps = segmenter_.components();
    const int n = comps.count();
    const int min_area = cfg_.segmentation.min_area;
    std::array<int, 3> top{0, 0, 0};
    for (int id = 1; id <= n; ++id) {
      if (comps.area(id) < min_area) continue;
      for (int slot = 0; slot < 3; ++slot) {
        if (top[slot] == 0 || comps.area(id) > comps.area(top[slot])) {
          for (int s = 2; s > slot; --s) top[s] = top[s - 1];
          top[slot] = id;
          break;
        }
      }
    }
    std::array<double, 3> sum_mag{0, 0, 0}, sum_dir{0, 0, 0}, count{0, 0, 0};
    const ImageView source =
        cfg_.gradient_source == GradientSource::raw ? img : ImageView(seg.quantised);
    if (top[0] != 0) {
      // Slot of every label: 0..2 for the three largest, 3 for the others and the background.
      slot_.assign(static_cast<std::size_t>(n) + 1, 3);
      for (int s = 0; s < 3; ++s) {
        if (top[s] != 0) slot_[static_cast<std::size_t>(top[s])] = static_cast<std::uint8_t>(s);
      }
      const std::int32_t* lab = comps.labels().data();
      for (Eigen::Index r = 0; r < rows_; ++r) {
        const std::int32_t* row = lab + r * cols_;
        const bool edge_row = r == 0 || r + 1 == rows_;
        for (Eigen::Index c = 0; c < cols_; ++c) {
          const std::int32_t id = row[c];
          const int slot = slot_[static_cast<std::size_t>(id)];
          if (slot == 3) continue;
          const bool edge = edge_row || c == 0 || c + 1 == cols_ || row[c - cols_] != id ||
                            row[c + cols_] != id || row[c - 1] != id || row[c + 1] != id;
          if (!edge) continue;
          const auto [gx, gy] = sobel_at(source, r, c);
          // sqrt, not hypot: Sobel sums of image values cannot overflow, and hypot costs about
          // 20 ns a call (equal to 1 ulp).
          sum_mag[slot] += std::sqrt(gx * gx + gy * gy);
          sum_dir[slot] += detail::fast_atan2(-gy, gx) * (180.0 / std::numbers::pi);
          count[slot] += 1;
        }
      }
    }
    for (int s = 0; s < 3; ++s) {
      const bool present = top[s] != 0;
      res.edge_features(14 + s) = present ? comps.area(top[s]) : 0.0;
      res.edge_features(17 + s) = present ? sum_mag[s] / count[s] : 0.0;
      res.edge_features(20 + s) = present ? sum_dir[s] / count[s] : 0.0;
    }
    res.contour_gradient = res.edge_features(17);
    res.edged = decider_.edged(res.edge_features);

    // Reconstruction and the hybrid vector.
    const ImageD& height =
        res.edged ? reconstructor_.rec_edged(seg) : reconstructor_.rec_edgeless(img, seg);
    detail::gradient_magnitude_into(height, res.hybrid.data());
    res.hybrid.tail<kRegionalFeatures>() = res.regional;
    res.label = classifier_.predict(res.hybrid);
    return res;
  }

  /// The last result.
  [[nodiscard]] const Recognition& result() const noexcept { return result_; }
  /// The last segmentation.
  [[nodiscard]] const Segmentation& segmentation() const noexcept { return segmenter_.result(); }
  /// The descriptors of the last image's HPRs.
  [[nodiscard]] const RegionProps& region() const noexcept { return analyzer_.result(); }
  /// The last reconstruction (height map).
  [[nodiscard]] const ImageD& reconstruction() const noexcept { return reconstructor_.height(); }
  /// The configuration.
  [[nodiscard]] const RecognizerConfig& config() const noexcept { return cfg_; }

 private:
  // Runs before any member allocates: sizes >= 1 and at most kMaxImagePixels pixels.
  static void checked_size(Eigen::Index rows, Eigen::Index cols) {
    if (rows < 1 || cols < 1) {
      throw std::invalid_argument("Recognizer: rows and cols must be >= 1, got " +
                                  std::to_string(rows) + " x " + std::to_string(cols));
    }
    detail::checked_pixels("Recognizer", rows, cols);
  }

  Eigen::Index rows_, cols_;
  RecognizerConfig cfg_;
  Decider decider_;
  Classifier classifier_;
  Segmenter segmenter_;
  RegionAnalyzer analyzer_;
  Reconstructor reconstructor_;
  std::vector<std::uint8_t> slot_;
  Recognition result_;
};

/// Runs `prototype`'s chain on `count` images, `image_at(i)` giving image i (anything an
/// ImageView binds to), on `threads` threads (0: every core). Each thread runs its own copy of
/// the prototype over a contiguous range of images, so the results are those of one Recognizer
/// run over the images in order. The classifier and decider must be safe to call from several
/// threads at once (the shipped ones are). Returns one Recognition per image.
template <class Decider, class Classifier, class ImageAt>
std::vector<Recognition> recognize_all(const Recognizer<Decider, Classifier>& prototype,
                                       std::size_t count, ImageAt&& image_at,
                                       unsigned threads = 0) {
  std::vector<Recognition> out(count);
  const std::size_t chunks = std::min<std::size_t>(resolve_threads(threads), count);
  parallel_for(chunks, threads, [&](std::size_t k) {
    Recognizer<Decider, Classifier> rec = prototype;
    const std::size_t begin = count * k / chunks;
    const std::size_t end = count * (k + 1) / chunks;
    for (std::size_t i = begin; i < end; ++i) out[i] = rec.recognize(image_at(i));
  });
  return out;
}

}  // namespace taxel::image
