// SPDX-License-Identifier: MIT
// taxel.image: k-means, segmentation, components, region properties, gradients,
// reconstruction and the recogniser, on 2-D images and 3-D stacks of frames.
#include <span>

#include "common.hpp"
#include "taxel/image.hpp"

namespace taxel::python {
namespace {

namespace im = taxel::image;

using ImageMap = Eigen::Map<const im::ImageD>;
using MaskMap = Eigen::Map<const im::Mask>;

constexpr std::pair<std::string_view, im::Polarity> kPolarities[] = {
    {"high_is_pressure", im::Polarity::high_is_pressure},
    {"dark_is_pressure", im::Polarity::dark_is_pressure}};
constexpr std::pair<std::string_view, im::PostProcess> kPost[] = {
    {"none", im::PostProcess::none},
    {"mean3x3", im::PostProcess::mean3x3},
    {"median3x3", im::PostProcess::median3x3}};
constexpr std::pair<std::string_view, im::Healing> kHealing[] = {
    {"linear", im::Healing::linear},
    {"row_mean", im::Healing::row_mean},
    {"none", im::Healing::none}};
constexpr std::pair<std::string_view, im::HeightSource> kSources[] = {
    {"raw", im::HeightSource::raw}, {"quantised", im::HeightSource::quantised}};
constexpr std::pair<std::string_view, im::GradientSource> kGradientSources[] = {
    {"raw", im::GradientSource::raw}, {"quantised", im::GradientSource::quantised}};

im::Connectivity connectivity_from(int c) {
  if (c != 4 && c != 8) {
    throw py::value_error("connectivity must be 4 or 8, got " + std::to_string(c));
  }
  return c == 4 ? im::Connectivity::four : im::Connectivity::eight;
}

/// Frame count, rows and columns of a 2-D image or a 3-D stack.
struct Frames {
  py::ssize_t frames, rows, cols;
  bool stacked;
};

Frames frames_of(const py::array& a, const char* what) {
  if (a.ndim() == 2) return {1, a.shape(0), a.shape(1), false};
  if (a.ndim() == 3) return {a.shape(0), a.shape(1), a.shape(2), true};
  throw py::value_error(std::string(what) +
                        ": expected an image (rows, cols) or a stack (frames, rows, cols), got " +
                        shape_text(a));
}

ImageMap frame(const ArrayD& a, const Frames& f, py::ssize_t i) {
  return {a.data() + i * f.rows * f.cols, f.rows, f.cols};
}

/// A stack of `f.frames` images of f.rows x f.cols (2-D when the input was 2-D).
template <class T>
py::array_t<T> stack_like(const Frames& f) {
  if (!f.stacked) return py::array_t<T>({f.rows, f.cols});
  return py::array_t<T>({f.frames, f.rows, f.cols});
}

/// Two maps of every frame of an image or stack, fn(frame, a, b) filling a and b, as a tuple of
/// two arrays shaped like the input. Runs without the GIL.
template <class Fn>
py::tuple two_maps(const ArrayD& image, const char* what, Fn&& fn) {
  const Frames f = frames_of(image, what);
  auto first = stack_like<double>(f);
  auto second = stack_like<double>(f);
  double* pa = first.mutable_data();
  double* pb = second.mutable_data();
  {
    py::gil_scoped_release release;
    im::ImageD a, b;
    for (py::ssize_t i = 0; i < f.frames; ++i) {
      fn(frame(image, f, i), a, b);
      pa = std::copy(a.data(), a.data() + a.size(), pa);
      pb = std::copy(b.data(), b.data() + b.size(), pb);
    }
  }
  return py::make_tuple(first, second);
}

py::dict props_dict(const im::RegionProps& p) {
  py::dict d;
  d["area"] = p.area;
  d["centroid"] = py::make_tuple(p.centroid.x(), p.centroid.y());
  d["bounding_box"] =
      py::make_tuple(p.bounding_box(0), p.bounding_box(1), p.bounding_box(2), p.bounding_box(3));
  d["major_axis_length"] = p.major_axis;
  d["minor_axis_length"] = p.minor_axis;
  d["eccentricity"] = p.eccentricity;
  d["orientation"] = p.orientation;
  d["convex_area"] = p.convex_area;
  ArrayD hull({static_cast<py::ssize_t>(p.convex_hull.size()), py::ssize_t{2}});
  for (std::size_t i = 0; i < p.convex_hull.size(); ++i) {
    hull.mutable_data()[2 * i] = p.convex_hull[i].x();
    hull.mutable_data()[2 * i + 1] = p.convex_hull[i].y();
  }
  d["convex_hull"] = hull;
  d["solidity"] = p.solidity;
  d["extent"] = p.extent;
  d["equiv_diameter"] = p.equiv_diameter;
  d["euler_number"] = p.euler_number;
  d["euler_number4"] = p.euler_number4;
  d["perimeter"] = p.perimeter;
  return d;
}

im::SegmentationConfig segmentation_config(int k, const std::string& polarity, int min_area,
                                           int connectivity, int histogram_levels) {
  return {k, enum_from(polarity, kPolarities, "polarity"), min_area,
          connectivity_from(connectivity), histogram_levels};
}

/// The Python Recognizer: the paper's chain with the gradient-threshold edge rule.
struct PyRecognizer {
  im::Recognizer<> recognizer;
  py::tuple args;  // (rows, cols, gradient_threshold, gradient_source, k, polarity, min_area,
                   // connectivity): what a pickled recogniser is made again from
};

PyRecognizer make_recognizer(py::ssize_t rows, py::ssize_t cols, double gradient_threshold,
                             const std::string& gradient_source, int k, const std::string& polarity,
                             int min_area, int connectivity) {
  im::RecognizerConfig cfg;
  cfg.segmentation = segmentation_config(k, polarity, min_area, connectivity, 65536);
  cfg.gradient_source = enum_from(gradient_source, kGradientSources, "gradient_source");
  return PyRecognizer{im::Recognizer<>(rows, cols, cfg, im::GradientThreshold{gradient_threshold}),
                      py::make_tuple(rows, cols, gradient_threshold, gradient_source, k, polarity,
                                     min_area, connectivity)};
}

}  // namespace

void bind_image(py::module_& root) {
  py::module_ m = root.def_submodule("image", R"doc(
Pressure images: 1-D k-means segmentation, high-pressure regions (HPR), region descriptors,
gradients, RecEdged / RecEdgeless reconstruction and the recogniser. Images are (rows, cols)
float arrays, row 0 at the top; stacks are (frames, rows, cols). Region descriptors follow
MATLAB's regionprops: 1-based (x, y) = (column, row) pixel coordinates, orientation in degrees
counter-clockwise with y up.)doc");
  m.attr("REGIONAL_FEATURE_NAMES") =
      std::vector<std::string>(im::kRegionalFeatureNames.begin(), im::kRegionalFeatureNames.end());
  m.attr("EDGE_FEATURE_NAMES") =
      std::vector<std::string>(im::kEdgeFeatureNames.begin(), im::kEdgeFeatureNames.end());

  py::class_<im::KMeans1dResult> cls_kmeans1dresult(m, "KMeans1dResult",
                                                    "A 1-D clustering, clusters ascending.");
  pickle_members(cls_kmeans1dresult, "KMeans1dResult", &im::KMeans1dResult::status,
                 &im::KMeans1dResult::message, &im::KMeans1dResult::k_requested,
                 &im::KMeans1dResult::k, &im::KMeans1dResult::centroids, &im::KMeans1dResult::lower,
                 &im::KMeans1dResult::upper, &im::KMeans1dResult::sizes, &im::KMeans1dResult::sse,
                 &im::KMeans1dResult::iterations);
  cls_kmeans1dresult
      .def_property_readonly(
          "status", [](const im::KMeans1dResult& r) { return std::string(to_string(r.status)); })
      .def_readonly("message", &im::KMeans1dResult::message, "why, when status is not 'ok'")
      .def_readonly("k", &im::KMeans1dResult::k,
                    "clusters found: min(k_requested, distinct values)")
      .def_readonly("k_requested", &im::KMeans1dResult::k_requested,
                    "the number of clusters asked for")
      .def_readonly("centroids", &im::KMeans1dResult::centroids, "cluster centres, ascending")
      .def_readonly("lower", &im::KMeans1dResult::lower, "smallest value of each cluster")
      .def_readonly("upper", &im::KMeans1dResult::upper, "largest value of each cluster")
      .def_readonly("sizes", &im::KMeans1dResult::sizes, "values in each cluster")
      .def_readonly("sse", &im::KMeans1dResult::sse, "within-cluster sum of squared deviations")
      .def_readonly("iterations", &im::KMeans1dResult::iterations,
                    "Lloyd iterations (0 for the exact solver)")
      .def(
          "labels",
          [](const im::KMeans1dResult& r, const ArrayD& values) {
            py::array_t<int> out(values.size());
            for (py::ssize_t i = 0; i < values.size(); ++i) {
              out.mutable_data()[i] = r.cluster_of(values.data()[i]);
            }
            return out;
          },
          py::arg("values"), "the cluster of each value (flattened)");

  m.def(
      "kmeans1d",
      [](const ArrayD& values, int k, const std::string& method, std::uint64_t seed,
         int max_iterations) {
        const std::span<const double> v(values.data(), static_cast<std::size_t>(values.size()));
        im::KMeans1dResult r;
        if (method == "exact") {
          py::gil_scoped_release release;
          r = im::kmeans1d(v, k);
        } else if (method == "lloyd") {
          py::gil_scoped_release release;
          r = im::kmeans1d_lloyd(v, {k, seed, max_iterations});
        } else {
          throw py::value_error("kmeans1d: method must be 'exact' or 'lloyd', got '" + method +
                                "'");
        }
        raise_unless_ok(r, true);
        return r;
      },
      py::arg("values"), py::arg("k") = 3, py::kw_only(), py::arg("method") = "exact",
      py::arg("seed") = 1, py::arg("max_iterations") = 100,
      "k-means of the (flattened) values: 'exact' (globally optimal, dynamic programming) or "
      "'lloyd' (k-means++ start). Raises ValueError for empty or non-finite values.");

  py::class_<im::Segmentation> cls_segmentation(m, "Segmentation",
                                                "The segmentation of one image.");
  pickle_members(cls_segmentation, "Segmentation", &im::Segmentation::status,
                 &im::Segmentation::message, &im::Segmentation::classes,
                 &im::Segmentation::quantised, &im::Segmentation::high, &im::Segmentation::high_raw,
                 &im::Segmentation::kmeans, &im::Segmentation::classes_count,
                 &im::Segmentation::regions, &im::Segmentation::background_level,
                 &im::Segmentation::high_level, &im::Segmentation::pixel_min,
                 &im::Segmentation::pixel_max, &im::Segmentation::pixel_mean);
  cls_segmentation
      .def_property_readonly(
          "classes", [](const im::Segmentation& s) { return s.classes; },
          "uint8 class per pixel: 0 background .. k-1 high pressure")
      .def_property_readonly(
          "quantised", [](const im::Segmentation& s) { return s.quantised; },
          "each pixel replaced by its cluster's centroid")
      .def_property_readonly(
          "high", [](const im::Segmentation& s) { return s.high; },
          "uint8 mask of the HPR pixels after removal of small regions")
      .def_property_readonly("high_raw", [](const im::Segmentation& s) { return s.high_raw; })
      .def_readonly("kmeans", &im::Segmentation::kmeans,
                    "the clustering of the pixel values (KMeans1dResult)")
      .def_readonly("regions", &im::Segmentation::regions, "HPR components kept")
      .def_readonly("background_level", &im::Segmentation::background_level,
                    "centroid of the background cluster")
      .def_readonly("high_level", &im::Segmentation::high_level,
                    "centroid of the high-pressure cluster")
      .def_readonly("pixel_min", &im::Segmentation::pixel_min, "smallest pixel value")
      .def_readonly("pixel_max", &im::Segmentation::pixel_max, "largest pixel value")
      .def_readonly("pixel_mean", &im::Segmentation::pixel_mean, "mean pixel value");

  // One body for segment (an image) and segment_stack (frames): every frame segmented by one
  // Segmenter, the GIL released per frame.
  const auto segment_frames = [](const ArrayD& image, const Frames& f, int k,
                                 const std::string& polarity, int min_area, int connectivity,
                                 int histogram_levels) {
    im::Segmenter seg(segmentation_config(k, polarity, min_area, connectivity, histogram_levels),
                      f.rows, f.cols);
    std::vector<im::Segmentation> out;
    for (py::ssize_t i = 0; i < f.frames; ++i) {
      {
        py::gil_scoped_release release;
        out.push_back(seg.run(frame(image, f, i)));
      }
      if (!out.back().ok()) {
        throw py::value_error((f.stacked ? "frame " + std::to_string(i) + ": " : "") +
                              out.back().message);
      }
    }
    return out;
  };
  m.def(
      "segment",
      [segment_frames](const ArrayD& image, int k, const std::string& polarity, int min_area,
                       int connectivity, int histogram_levels) {
        if (image.ndim() == 3) {
          throw py::value_error("segment: expected one image (rows, cols), got a stack " +
                                shape_text(image) + "; use segment_stack for frames");
        }
        const Frames f = frames_of(image, "segment");
        return std::move(
            segment_frames(image, f, k, polarity, min_area, connectivity, histogram_levels)
                .front());
      },
      py::arg("image"), py::kw_only(), py::arg("k") = 3, py::arg("polarity") = "high_is_pressure",
      py::arg("min_area") = 50, py::arg("connectivity") = 8, py::arg("histogram_levels") = 65536,
      "Segments an image (rows, cols): k-means of the pixel values; the top cluster's "
      "8-connected regions of at least min_area pixels are the HPR.");
  m.def(
      "segment_stack",
      [segment_frames](const ArrayD& images, int k, const std::string& polarity, int min_area,
                       int connectivity, int histogram_levels) {
        if (images.ndim() != 3) {
          throw py::value_error("segment_stack: expected a stack (frames, rows, cols), got " +
                                shape_text(images) + "; use segment for one image");
        }
        return segment_frames(images, frames_of(images, "segment_stack"), k, polarity, min_area,
                              connectivity, histogram_levels);
      },
      py::arg("images"), py::kw_only(), py::arg("k") = 3, py::arg("polarity") = "high_is_pressure",
      py::arg("min_area") = 50, py::arg("connectivity") = 8, py::arg("histogram_levels") = 65536,
      "Segments each frame of a stack (frames, rows, cols) as segment does: a list of "
      "Segmentation.");

  m.def(
      "label",
      [](const ArrayU8& mask, int connectivity) {
        require_shape(mask, {-1, -1}, "label", "(rows, cols)");
        im::Components comp(mask.shape(0), mask.shape(1));
        const int n = comp.compute(MaskMap(mask.data(), mask.shape(0), mask.shape(1)),
                                   connectivity_from(connectivity));
        return py::make_tuple(im::Labels(comp.labels()), n);
      },
      py::arg("mask"), py::arg("connectivity") = 8,
      "(labels, count): connected components of the non-zero pixels, numbered from 1 in raster "
      "order (MATLAB's bwlabel numbers in column order).");

  m.def(
      "region_props",
      [](const ArrayU8& mask, bool zero_based, bool convex, bool perimeter) {
        require_shape(mask, {-1, -1}, "region_props", "(rows, cols)");
        im::RegionProps p;
        {
          py::gil_scoped_release release;
          p = im::region_props(MaskMap(mask.data(), mask.shape(0), mask.shape(1)),
                               {zero_based, convex, perimeter});
        }
        return props_dict(p);
      },
      py::arg("mask"), py::kw_only(), py::arg("zero_based") = false, py::arg("convex") = true,
      py::arg("perimeter") = true,
      "Descriptors of the non-zero pixels of `mask` as one region (MATLAB's regionprops of a "
      "logical image): area, centroid (x, y), bounding_box (ulx, uly, width, height) on pixel "
      "edges, major/minor_axis_length, eccentricity, orientation [deg], convex_area, "
      "convex_hull (K, 2) (x, y), solidity, extent, equiv_diameter, euler_number (8-connected "
      "objects), euler_number4, perimeter. Coordinates are 1-based unless zero_based.");

  m.def(
      "regionprops",
      [](const ArrayI& labels, bool zero_based, bool convex, bool perimeter) {
        require_shape(labels, {-1, -1}, "regionprops", "(rows, cols)");
        const py::ssize_t rows = labels.shape(0), cols = labels.shape(1);
        int top = 0;
        for (py::ssize_t i = 0; i < labels.size(); ++i) {
          if (labels.data()[i] < 0) throw py::value_error("regionprops: negative label");
          top = std::max(top, labels.data()[i]);
        }
        im::RegionAnalyzer analyzer({zero_based, convex, perimeter}, rows, cols);
        im::Mask mask(rows, cols);
        py::list out;
        for (int id = 1; id <= top; ++id) {
          bool any = false;
          for (py::ssize_t i = 0; i < labels.size(); ++i) {
            mask.data()[i] = labels.data()[i] == id ? 1 : 0;
            any = any || mask.data()[i];
          }
          if (!any) continue;
          py::dict d = props_dict(analyzer.compute(mask));
          d["label"] = id;
          out.append(d);
        }
        return out;
      },
      py::arg("labels"), py::kw_only(), py::arg("zero_based") = false, py::arg("convex") = true,
      py::arg("perimeter") = true,
      "A dict of descriptors (see region_props) per label 1..max of a label image, with its "
      "'label'; absent labels are skipped.");

  m.def(
      "gradient",
      [](const ArrayD& image) {
        im::ImageD gx, gy;  // scratch
        return two_maps(image, "gradient",
                        [&](const ImageMap& img, im::ImageD& mag, im::ImageD& dir) {
                          im::gradient(img, mag, dir, gx, gy);
                        });
      },
      py::arg("image"),
      "(magnitude, direction): MATLAB's imgradient with Sobel kernels and replicated borders; "
      "direction in degrees in (-180, 180], counter-clockwise from +x with y up.");

  m.def(
      "sobel",
      [](const ArrayD& image) {
        return two_maps(image, "sobel", [](const ImageMap& img, im::ImageD& gx, im::ImageD& gy) {
          im::sobel(img, gx, gy);
        });
      },
      py::arg("image"),
      "(gx, gy): Sobel derivatives with replicated borders as MATLAB's imgradientxy; gx grows "
      "to the right, gy towards larger row indices (down).");

  m.def(
      "contour",
      [](const ArrayU8& mask) {
        require_shape(mask, {-1, -1}, "contour", "(rows, cols)");
        im::Mask out;
        im::contour(MaskMap(mask.data(), mask.shape(0), mask.shape(1)), out);
        return out;
      },
      py::arg("mask"), "The contour pixels of a region (MATLAB's bwperim, 4-connected).");

  m.def(
      "rec_edged",
      [](const im::Segmentation& seg, double k, double background_fraction,
         bool swap_edge_condition, bool fill_whole_row, bool keep_level_on_skipped_rows,
         const std::string& postprocess) {
        const im::RecEdgedConfig cfg{k,
                                     background_fraction,
                                     swap_edge_condition,
                                     fill_whole_row,
                                     keep_level_on_skipped_rows,
                                     enum_from(postprocess, kPost, "postprocess")};
        im::Reconstructor rec(cfg, {}, seg.classes.rows(), seg.classes.cols());
        return im::ImageD(rec.rec_edged(seg));
      },
      py::arg("segmentation"), py::kw_only(), py::arg("k") = 0.5,
      py::arg("background_fraction") = 0.5, py::arg("swap_edge_condition") = false,
      py::arg("fill_whole_row") = false, py::arg("keep_level_on_skipped_rows") = false,
      py::arg("postprocess") = "none",
      "RecEdged: a height map from a segmentation by a row-scanning two-state machine; steps of "
      "k * high_level.");

  m.def(
      "rec_edgeless",
      [](const ArrayD& image, const im::Segmentation& seg, double background_fraction, int degree,
         const std::string& healing, const std::string& source) {
        require_shape(image, {seg.classes.rows(), seg.classes.cols()}, "rec_edgeless",
                      "(rows, cols) like the segmentation");
        const im::RecEdgelessConfig cfg{background_fraction, degree,
                                        enum_from(healing, kHealing, "healing"),
                                        enum_from(source, kSources, "source")};
        im::Reconstructor rec({}, cfg, seg.classes.rows(), seg.classes.cols());
        return im::ImageD(
            rec.rec_edgeless(ImageMap(image.data(), image.shape(0), image.shape(1)), seg));
      },
      py::arg("image"), py::arg("segmentation"), py::kw_only(),
      py::arg("background_fraction") = 0.5, py::arg("degree") = 2, py::arg("healing") = "linear",
      py::arg("source") = "raw",
      "RecEdgeless: a height map from the image, gaps healed within rows and every column "
      "replaced by its least-squares polynomial of `degree`.");

  py::class_<im::Recognition> cls_recognition(m, "Recognition",
                                              "The recogniser's result for one image.");
  pickle_members(
      cls_recognition, "Recognition", &im::Recognition::status, &im::Recognition::message,
      &im::Recognition::edged, &im::Recognition::contour_gradient, &im::Recognition::regional,
      &im::Recognition::edge_features, &im::Recognition::hybrid, &im::Recognition::label);
  cls_recognition.def_readonly("edged", &im::Recognition::edged, "the edged/edgeless decision")
      .def_readonly("contour_gradient", &im::Recognition::contour_gradient,
                    "mean contour gradient magnitude of the largest HPR (feature 18)")
      .def_readonly("regional", &im::Recognition::regional, "the 11 regional features")
      .def_readonly("edge_features", &im::Recognition::edge_features, "the 23 edge features")
      .def_readonly(
          "hybrid", &im::Recognition::hybrid,
          "rows*cols gradient magnitudes (row-major) followed by the 11 regional features");

  py::class_<PyRecognizer> cls_recognizer(m, "Recognizer", R"doc(
The second paper's chain for images of rows x cols: segmentation, HPR descriptors, contour
gradients, the edged/edgeless decision (mean contour gradient of the largest HPR above
gradient_threshold) and the feature vectors.)doc");
  pickle_with(
      cls_recognizer, "Recognizer", [](const PyRecognizer& r) { return r.args; },
      [](const py::tuple& a) {
        if (a.size() != 8) throw py::value_error("Recognizer: damaged pickled state");
        return make_recognizer(a[0].cast<py::ssize_t>(), a[1].cast<py::ssize_t>(),
                               a[2].cast<double>(), a[3].cast<std::string>(), a[4].cast<int>(),
                               a[5].cast<std::string>(), a[6].cast<int>(), a[7].cast<int>());
      });
  cls_recognizer
      .def(py::init([](py::ssize_t rows, py::ssize_t cols, double gradient_threshold,
                       const std::string& gradient_source, int k, const std::string& polarity,
                       int min_area, int connectivity) {
             return make_recognizer(rows, cols, gradient_threshold, gradient_source, k, polarity,
                                    min_area, connectivity);
           }),
           py::arg("rows") = 32, py::arg("cols") = 32, py::kw_only(),
           py::arg("gradient_threshold") = 25.0, py::arg("gradient_source") = "raw",
           py::arg("k") = 3, py::arg("polarity") = "high_is_pressure", py::arg("min_area") = 50,
           py::arg("connectivity") = 8)
      .def(
          "recognize",
          [](PyRecognizer& r, const ArrayD& image) {
            require_shape(image, {-1, -1}, "recognize", "(rows, cols)");
            im::Recognition out;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&r);  // its workspace changes (common.hpp)
              out = r.recognizer.recognize(ImageMap(image.data(), image.shape(0), image.shape(1)));
            }
            raise_unless_ok(out);
            return out;
          },
          py::arg("image"), "Runs the chain on one image; ValueError for a wrong size or NaN.")
      .def(
          "features",
          [](const PyRecognizer& r, const ArrayD& images, unsigned threads) {
            const Frames f = frames_of(images, "features");
            const auto n = f.frames;
            std::vector<im::Recognition> all;
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&r);
              all = im::recognize_all(
                  r.recognizer, static_cast<std::size_t>(n),
                  [&](std::size_t i) { return frame(images, f, static_cast<py::ssize_t>(i)); },
                  threads);
            }
            ArrayD regional({n, py::ssize_t{im::kRegionalFeatures}});
            ArrayD edge({n, py::ssize_t{im::kEdgeFeatures}});
            ArrayD hybrid({n, f.rows * f.cols + im::kRegionalFeatures});
            py::array_t<bool> edged(n);
            ArrayD gm(n);
            for (py::ssize_t i = 0; i < n; ++i) {
              const im::Recognition& x = all[static_cast<std::size_t>(i)];
              if (!x.ok()) throw py::value_error("frame " + std::to_string(i) + ": " + x.message);
              std::copy_n(x.regional.data(), x.regional.size(),
                          regional.mutable_data() + i * x.regional.size());
              std::copy_n(x.edge_features.data(), x.edge_features.size(),
                          edge.mutable_data() + i * x.edge_features.size());
              std::copy_n(x.hybrid.data(), x.hybrid.size(),
                          hybrid.mutable_data() + i * x.hybrid.size());
              edged.mutable_data()[i] = x.edged;
              gm.mutable_data()[i] = x.contour_gradient;
            }
            py::dict d;
            d["regional"] = regional;
            d["edge"] = edge;
            d["hybrid"] = hybrid;
            d["edged"] = edged;
            d["contour_gradient"] = gm;
            return d;
          },
          py::arg("images"), py::kw_only(), py::arg("threads") = 0,
          "Features of an image or a stack: a dict of 'regional' (F, 11), 'edge' (F, 23), "
          "'hybrid' (F, rows*cols + 11), 'edged' (F,) and 'contour_gradient' (F,). Frames are "
          "shared out over `threads` threads (0: every core), each with its own copy of the "
          "recogniser; the result does not depend on it.");
}

}  // namespace taxel::python
