// SPDX-License-Identifier: MIT
// taxel.registration: Target, Icp (both errors, every kernel) and ObjectLibrary.
#include <span>

#include "common.hpp"
#include "taxel/registration.hpp"

namespace taxel::python {
namespace {

namespace reg = taxel::registration;

std::span<const Vec3d> points_view(const ArrayD& a, const char* what) {
  require_shape(a, {-1, 3}, what, "(N, 3)");
  return {reinterpret_cast<const Vec3d*>(a.data()), static_cast<std::size_t>(a.shape(0))};
}

constexpr std::pair<std::string_view, int> kErrors[] = {{"point_to_plane", 0},
                                                        {"point_to_point", 1}};
constexpr std::pair<std::string_view, int> kKernels[] = {
    {"none", 0}, {"huber", 1}, {"cauchy", 2}, {"geman_mcclure", 3}, {"tukey", 4}};

/// The Python Icp: the error and kernel chosen by name.
struct PyIcp {
  std::string error, kernel;
  double kernel_scale;
  reg::IcpConfig config;
};

template <class E, class K>
reg::IcpResult align_with(const PyIcp& icp, K kernel, const reg::Target<double>& target,
                          std::span<const Vec3d> source, const Isometry3d& initial) {
  reg::Icp<E, K> solver(icp.config, kernel);
  return solver.align(target, source, initial);
}

template <class E>
reg::IcpResult align_error(const PyIcp& icp, const reg::Target<double>& target,
                           std::span<const Vec3d> source, const Isometry3d& initial) {
  const double s = icp.kernel_scale;
  switch (enum_from(icp.kernel, kKernels, "kernel")) {
    case 1:
      return align_with<E>(icp, reg::Huber{s}, target, source, initial);
    case 2:
      return align_with<E>(icp, reg::Cauchy{s}, target, source, initial);
    case 3:
      return align_with<E>(icp, reg::GemanMcClure{s}, target, source, initial);
    case 4:
      return align_with<E>(icp, reg::Tukey{s}, target, source, initial);
    default:
      return align_with<E>(icp, reg::NoKernel{}, target, source, initial);
  }
}

double default_scale(const std::string& kernel) {
  switch (enum_from(kernel, kKernels, "kernel")) {
    case 1:
      return reg::Huber{}.scale;
    case 2:
      return reg::Cauchy{}.scale;
    case 3:
      return reg::GemanMcClure{}.scale;
    case 4:
      return reg::Tukey{}.scale;
    default:
      return 0.0;
  }
}

/// A target's points, normals and configuration: what a pickled Target is made again from.
py::tuple target_state(const reg::Target<double>& t) {
  const reg::TargetConfig& c = t.config();
  return py::make_tuple(points_array(t.points()), points_array(t.normals()), c.normal_neighbors,
                        c.grid_spacing_factor, c.field_cell, c.field_margin, c.field_max_cells);
}

/// The configuration in a target_state() tuple.
reg::TargetConfig target_config(const py::tuple& a) {
  if (a.size() != 7) throw py::value_error("Target: damaged pickled state");
  reg::TargetConfig c;
  c.normal_neighbors = a[2].cast<int>();
  c.grid_spacing_factor = a[3].cast<double>();
  c.field_cell = a[4].cast<double>();
  c.field_margin = a[5].cast<double>();
  c.field_max_cells = a[6].cast<std::size_t>();
  return c;
}

/// The points and normals of a target_state() tuple, as a cloud.
Cloud target_cloud(const py::tuple& a) {
  return cloud_from(a[0].cast<ArrayD>(), a[1].cast<ArrayD>(), "pickled points");
}

/// The target of target_state(): the normals as they were, not estimated again.
reg::Target<double> target_from(const py::tuple& a) {
  const reg::TargetConfig c = target_config(a);
  Cloud cloud = target_cloud(a);
  py::gil_scoped_release release;
  return reg::Target<double>(std::move(cloud), c);
}

}  // namespace

void bind_registration(py::module_& root) {
  py::module_ m = root.def_submodule("registration", "ICP alignment and object recognition");

  py::class_<reg::Target<double>> target_cls(m, "Target", R"doc(
A model prepared for registration: points [m], unit normals (given, or estimated by PCA over
`normal_neighbors` points and oriented away from the centroid), a nearest-neighbour grid and,
with field_cell > 0 [m], a closest-point field for approximate correspondences.)doc");
  pickle_with<false>(target_cls, "Target", target_state, target_from);
  target_cls
      .def(py::init([](const ArrayD& points, const std::optional<ArrayD>& normals,
                       int normal_neighbors, bool recompute_normals, double grid_spacing_factor,
                       double field_cell, double field_margin, std::size_t field_max_cells) {
             reg::TargetConfig cfg;
             cfg.normal_neighbors = normal_neighbors;
             cfg.recompute_normals = recompute_normals;
             cfg.grid_spacing_factor = grid_spacing_factor;
             cfg.field_cell = field_cell;
             cfg.field_margin = field_margin;
             cfg.field_max_cells = field_max_cells;
             Cloud c = cloud_from(points, normals, "points");
             py::gil_scoped_release release;
             return reg::Target<double>(std::move(c), cfg);
           }),
           py::arg("points"), py::arg("normals") = py::none(), py::kw_only(),
           py::arg("normal_neighbors") = 12, py::arg("recompute_normals") = false,
           py::arg("grid_spacing_factor") = 4.0, py::arg("field_cell") = 0.0,
           py::arg("field_margin") = 0.02, py::arg("field_max_cells") = std::size_t{1} << 22)
      .def(py::init([](const Cloud& cloud, int normal_neighbors) {
             reg::TargetConfig cfg;
             cfg.normal_neighbors = normal_neighbors;
             py::gil_scoped_release release;
             return reg::Target<double>(cloud, cfg);
           }),
           py::arg("cloud"), py::kw_only(), py::arg("normal_neighbors") = 12,
           "A target from a PointCloud (its normals when it has them).")
      .def("__len__", &reg::Target<double>::size)
      .def_property_readonly("points",
                             [](const reg::Target<double>& t) { return points_array(t.points()); })
      .def_property_readonly("normals",
                             [](const reg::Target<double>& t) { return points_array(t.normals()); })
      .def(
          "nearest",
          [](const reg::Target<double>& t, const ArrayD& queries) {
            const auto q = points_view(queries, "queries");
            py::array_t<std::int64_t> ids(static_cast<py::ssize_t>(q.size()));
            py::array_t<double> dist(static_cast<py::ssize_t>(q.size()));
            {
              py::gil_scoped_release release;
              for (std::size_t i = 0; i < q.size(); ++i) {
                const auto hit = t.nearest_within(q[i], std::numeric_limits<double>::infinity());
                ids.mutable_data()[i] = hit ? std::int64_t{hit->id} : -1;
                dist.mutable_data()[i] = hit ? std::sqrt(hit->squared_distance)
                                             : std::numeric_limits<double>::quiet_NaN();
              }
            }
            return py::make_tuple(ids, dist);
          },
          py::arg("queries"),
          "(ids, distances [m]) of the closest target point to each (N, 3) query; -1 and NaN "
          "for a non-finite query");

  py::class_<reg::IcpResult> cls_icpresult(m, "IcpResult", "The outcome of one alignment.");
  pickle_members(cls_icpresult, "IcpResult", &reg::IcpResult::status, &reg::IcpResult::message,
                 &reg::IcpResult::transform, &reg::IcpResult::rmse,
                 &reg::IcpResult::inlier_fraction, &reg::IcpResult::inliers,
                 &reg::IcpResult::skipped, &reg::IcpResult::iterations,
                 &reg::IcpResult::information);
  cls_icpresult
      .def_property_readonly(
          "status", [](const reg::IcpResult& r) { return std::string(to_string(r.status)); },
          "'ok', 'not_converged', 'degenerate' or 'invalid_input'")
      .def_readonly("message", &reg::IcpResult::message, "why, when status is not 'ok'")
      .def_property_readonly("ok", [](const reg::IcpResult& r) { return r.ok(); })
      .def_property_readonly(
          "transform", [](const reg::IcpResult& r) { return pose_array(r.transform); },
          "T_target_source, a 4x4 matrix")
      .def_readonly("rmse", &reg::IcpResult::rmse, "RMS distance of the inlier pairs [m]")
      .def_readonly("inlier_fraction", &reg::IcpResult::inlier_fraction,
                    "inliers / finite source points")
      .def_readonly("inliers", &reg::IcpResult::inliers,
                    "pairs kept by the distance gate and trimming")
      .def_readonly("skipped", &reg::IcpResult::skipped, "non-finite source points ignored")
      .def_readonly("iterations", &reg::IcpResult::iterations, "updates applied")
      .def("__repr__", [](const reg::IcpResult& r) {
        return "IcpResult(status='" + std::string(to_string(r.status)) +
               "', rmse=" + std::to_string(r.rmse) +
               ", iterations=" + std::to_string(r.iterations) + ")";
      });

  py::class_<PyIcp> cls_icp(m, "Icp", R"doc(
Iterative closest point. error: 'point_to_plane' (default) or 'point_to_point'; kernel:
'none', 'huber', 'cauchy', 'geman_mcclure' or 'tukey', with `kernel_scale` [m] (None: the
kernel's default, 1 mm; 3 mm for Tukey). Distances in metres, angles in radians.)doc");
  pickle_with(
      cls_icp, "Icp",
      [](const PyIcp& i) {
        const reg::IcpConfig& c = i.config;
        return py::make_tuple(i.error, i.kernel, i.kernel_scale, c.max_iterations, c.max_distance,
                              c.trim_fraction, c.translation_tolerance, c.rotation_tolerance,
                              c.relative_error_tolerance, c.min_correspondences, c.approximate,
                              c.coarse_points);
      },
      [](const py::tuple& t) {
        if (t.size() != 12) throw py::value_error("Icp: damaged pickled state");
        reg::IcpConfig c{t[3].cast<int>(),         t[4].cast<double>(), t[5].cast<double>(),
                         t[6].cast<double>(),      t[7].cast<double>(), t[8].cast<double>(),
                         t[9].cast<std::size_t>(), t[10].cast<bool>(),  t[11].cast<std::size_t>()};
        (void)reg::Icp<>(c);
        return PyIcp{t[0].cast<std::string>(), t[1].cast<std::string>(), t[2].cast<double>(), c};
      });
  cls_icp
      .def(
          py::init([](const std::string& error, const std::string& kernel,
                      std::optional<double> kernel_scale, int max_iterations, double max_distance,
                      double trim_fraction, double translation_tolerance, double rotation_tolerance,
                      double relative_error_tolerance, std::size_t min_correspondences,
                      bool approximate, std::size_t coarse_points) {
            enum_from(error, kErrors, "error");
            reg::IcpConfig cfg{max_iterations,        max_distance,       trim_fraction,
                               translation_tolerance, rotation_tolerance, relative_error_tolerance,
                               min_correspondences,   approximate,        coarse_points};
            (void)reg::Icp<>(cfg);  // validates the options
            const double scale = kernel_scale.value_or(default_scale(kernel));
            if (kernel != "none" && (!(scale > 0) || !std::isfinite(scale))) {
              throw py::value_error("Icp: kernel_scale must be finite and > 0 [m]");
            }
            return PyIcp{error, kernel, scale, cfg};
          }),
          py::arg("error") = "point_to_plane", py::arg("kernel") = "none", py::kw_only(),
          py::arg("kernel_scale") = py::none(), py::arg("max_iterations") = 50,
          py::arg("max_distance") = std::numeric_limits<double>::infinity(),
          py::arg("trim_fraction") = 0.0, py::arg("translation_tolerance") = 1e-6,
          py::arg("rotation_tolerance") = 1e-6, py::arg("relative_error_tolerance") = 0.0,
          py::arg("min_correspondences") = 0, py::arg("approximate") = false,
          py::arg("coarse_points") = 0)
      .def_readonly("error", &PyIcp::error, "'point_to_plane' or 'point_to_point'")
      .def_readonly("kernel", &PyIcp::kernel, "the robust kernel's name")
      .def_readonly("kernel_scale", &PyIcp::kernel_scale, "the kernel's scale [m]")
      .def(
          "align",
          [](const PyIcp& icp, const reg::Target<double>& target, const ArrayD& source,
             const std::optional<ArrayD>& initial) {
            const auto src = points_view(source, "source");
            const Isometry3d t0 = initial ? pose_from(*initial, "initial") : Isometry3d::Identity();
            py::gil_scoped_release release;
            return icp.error == "point_to_point"
                       ? align_error<reg::PointToPoint>(icp, target, src, t0)
                       : align_error<reg::PointToPlane>(icp, target, src, t0);
          },
          py::arg("target"), py::arg("source"), py::arg("initial") = py::none(),
          "Aligns source (N, 3) [m] to target from `initial` (4x4, default identity). Returns an "
          "IcpResult; its transform maps source points into the target frame.");

  py::class_<reg::ModelMatch> cls_modelmatch(m, "ModelMatch",
                                             "How well one model explains the cloud.");
  pickle_members(cls_modelmatch, "ModelMatch", &reg::ModelMatch::name, &reg::ModelMatch::model,
                 &reg::ModelMatch::score, &reg::ModelMatch::rmse, &reg::ModelMatch::inlier_fraction,
                 &reg::ModelMatch::transform, &reg::ModelMatch::icp_status, &reg::ModelMatch::exact,
                 &reg::ModelMatch::starts, &reg::ModelMatch::starts_stopped_early);
  cls_modelmatch.def_readonly("name", &reg::ModelMatch::name, "the model's name")
      .def_readonly("model", &reg::ModelMatch::model, "index in the library")
      .def_readonly("score", &reg::ModelMatch::score, "truncated RMS distance [m], lower is better")
      .def_readonly("rmse", &reg::ModelMatch::rmse, "ICP inlier RMS distance [m]")
      .def_readonly("inlier_fraction", &reg::ModelMatch::inlier_fraction,
                    "ICP inliers / cloud points")
      .def_property_readonly(
          "transform", [](const reg::ModelMatch& r) { return pose_array(r.transform); },
          "T_model_cloud, a 4x4 matrix")
      .def_property_readonly(
          "icp_status",
          [](const reg::ModelMatch& r) { return std::string(to_string(r.icp_status)); })
      .def_readonly("exact", &reg::ModelMatch::exact, "refined with exact correspondences")
      .def_readonly("starts", &reg::ModelMatch::starts, "starts tried")
      .def("__repr__", [](const reg::ModelMatch& r) {
        return "ModelMatch(name='" + r.name + "', score=" + std::to_string(r.score) + ")";
      });

  py::class_<reg::ObjectRecognition> cls_objectrecognition(m, "ObjectRecognition",
                                                           "The answer of recognize().");
  pickle_members(cls_objectrecognition, "ObjectRecognition", &reg::ObjectRecognition::status,
                 &reg::ObjectRecognition::message, &reg::ObjectRecognition::ranking,
                 &reg::ObjectRecognition::best, &reg::ObjectRecognition::unknown,
                 &reg::ObjectRecognition::margin);
  cls_objectrecognition
      .def_property_readonly(
          "status",
          [](const reg::ObjectRecognition& r) { return std::string(to_string(r.status)); })
      .def_readonly("message", &reg::ObjectRecognition::message, "why, when status is not 'ok'")
      .def_readonly("ranking", &reg::ObjectRecognition::ranking, "ModelMatch list, best first")
      .def_readonly("best", &reg::ObjectRecognition::best, "the best model's name, or 'unknown'")
      .def_readonly("unknown", &reg::ObjectRecognition::unknown,
                    "no model fits within the threshold")
      .def_readonly("margin", &reg::ObjectRecognition::margin,
                    "second score - best score [m] (0 with one model)")
      .def("__repr__", [](const reg::ObjectRecognition& r) {
        return "ObjectRecognition(best='" + r.best + "', margin=" + std::to_string(r.margin) + ")";
      });

  const reg::LibraryConfig kLib{};
  py::class_<reg::ObjectLibrary<double>> library_cls(m, "ObjectLibrary", R"doc(
Named object models; recognize() ranks them by how well each explains a cloud (multi-start
point-to-plane ICP, then a truncated RMS score [m]). One recognition shares its starts out over
`threads` threads (0: every core); the answer does not depend on the number.)doc");
  pickle_with<false>(
      library_cls, "ObjectLibrary",
      [](const reg::ObjectLibrary<double>& lib) {
        const auto lock = read_lock(&lib);
        const reg::LibraryConfig& c = lib.config();
        py::list models;
        for (std::size_t i = 0; i < lib.size(); ++i) {
          models.append(py::make_tuple(lib.name(i), target_state(lib.target(i))));
        }
        return py::make_tuple(
            py::make_tuple(c.coarse_iterations, c.coarse_points, c.refine_points, c.coarse_trim,
                           c.pca_starts, c.rotation_starts, c.refine_best, c.exact_models,
                           c.hopeless_factor, c.field_cell, c.score_gate, c.unknown_score,
                           c.threads),
            models);
      },
      [](const py::tuple& a) {
        const auto c = a[0].cast<py::tuple>();
        if (a.size() != 2 || c.size() != 13) {
          throw py::value_error("ObjectLibrary: damaged pickled state");
        }
        reg::LibraryConfig cfg;
        cfg.coarse_iterations = c[0].cast<int>();
        cfg.coarse_points = c[1].cast<std::size_t>();
        cfg.refine_points = c[2].cast<std::size_t>();
        cfg.coarse_trim = c[3].cast<double>();
        cfg.pca_starts = c[4].cast<bool>();
        cfg.rotation_starts = c[5].cast<int>();
        cfg.refine_best = c[6].cast<int>();
        cfg.exact_models = c[7].cast<int>();
        cfg.hopeless_factor = c[8].cast<double>();
        cfg.field_cell = c[9].cast<double>();
        cfg.score_gate = c[10].cast<double>();
        cfg.unknown_score = c[11].cast<double>();
        cfg.threads = c[12].cast<unsigned>();
        reg::ObjectLibrary<double> lib(cfg);
        for (const auto& item : a[1].cast<py::list>()) {
          const auto model = item.cast<py::tuple>();
          const auto t = model[1].cast<py::tuple>();
          lib.add(model[0].cast<std::string>(), target_cloud(t), target_config(t));
        }
        return lib;
      });
  library_cls
      .def(py::init([](int coarse_iterations, std::size_t coarse_points, std::size_t refine_points,
                       double coarse_trim, bool pca_starts, int rotation_starts, int refine_best,
                       int exact_models, double hopeless_factor, double field_cell,
                       double score_gate, double unknown_score, unsigned threads) {
             reg::LibraryConfig c;
             c.coarse_iterations = coarse_iterations;
             c.coarse_points = coarse_points;
             c.refine_points = refine_points;
             c.coarse_trim = coarse_trim;
             c.pca_starts = pca_starts;
             c.rotation_starts = rotation_starts;
             c.refine_best = refine_best;
             c.exact_models = exact_models;
             c.hopeless_factor = hopeless_factor;
             c.field_cell = field_cell;
             c.score_gate = score_gate;
             c.unknown_score = unknown_score;
             c.threads = threads;
             return reg::ObjectLibrary<double>(c);
           }),
           // The defaults are LibraryConfig's own, so the two cannot drift apart.
           py::kw_only(), py::arg("coarse_iterations") = kLib.coarse_iterations,
           py::arg("coarse_points") = kLib.coarse_points,
           py::arg("refine_points") = kLib.refine_points, py::arg("coarse_trim") = kLib.coarse_trim,
           py::arg("pca_starts") = kLib.pca_starts,
           py::arg("rotation_starts") = kLib.rotation_starts,
           py::arg("refine_best") = kLib.refine_best, py::arg("exact_models") = kLib.exact_models,
           py::arg("hopeless_factor") = kLib.hopeless_factor,
           py::arg("field_cell") = kLib.field_cell, py::arg("score_gate") = kLib.score_gate,
           py::arg("unknown_score") = kLib.unknown_score, py::arg("threads") = kLib.threads)
      .def(
          "add",
          [](reg::ObjectLibrary<double>& lib, std::string name, const ArrayD& points,
             const std::optional<ArrayD>& normals, int normal_neighbors) {
            reg::TargetConfig t;
            t.normal_neighbors = normal_neighbors;
            Cloud c = cloud_from(points, normals, "points");
            py::gil_scoped_release release;
            const auto lock = write_lock(&lib);  // common.hpp: object_mutex
            lib.add(std::move(name), std::move(c), t);
          },
          py::arg("name"), py::arg("points"), py::arg("normals") = py::none(), py::kw_only(),
          py::arg("normal_neighbors") = 12, "Adds a model: (N, 3) points [m], optional normals.")
      .def("__len__",
           [](const reg::ObjectLibrary<double>& lib) {
             const auto lock = read_lock(&lib);
             return lib.size();
           })
      .def_property_readonly("names",
                             [](const reg::ObjectLibrary<double>& lib) {
                               const auto lock = read_lock(&lib);
                               std::vector<std::string> out;
                               for (std::size_t i = 0; i < lib.size(); ++i)
                                 out.push_back(lib.name(i));
                               return out;
                             })
      .def(
          "recognize",
          [](const reg::ObjectLibrary<double>& lib, const ArrayD& points) {
            Cloud c = cloud_from(points, std::nullopt, "points");
            py::gil_scoped_release release;
            const auto lock = read_lock(&lib);
            return lib.recognize(c);
          },
          py::arg("points"),
          "Ranks the models for a cloud of (N, 3) points [m]; the GIL is released, so threads "
          "may recognise at once.");
}

}  // namespace taxel::python
