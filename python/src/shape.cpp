// SPDX-License-Identifier: MIT
// taxel.shape: the Gaussian-process implicit surface with its uncertainty, its mesh, the
// scoring of candidate touches, the Explorer that runs the loop, and the recognition belief.
#include <random>

#include "common.hpp"
#include "taxel/shape/explorer.hpp"
#include "taxel/shape/implicit_surface.hpp"
#include "taxel/shape/marching.hpp"
#include "taxel/shape/next_touch.hpp"
#include "taxel/shape/recognition.hpp"
#include "taxel/shape/surface_mesh.hpp"

namespace taxel::python {
namespace {

namespace sh = taxel::shape;
using Surface = sh::ImplicitSurface<sh::Matern32>;
using Explorer = sh::Explorer<sh::Matern32>;

Vec3d vec3(const ArrayD& a, const char* what) {
  require_shape(a, {3}, what, "(3,)");
  return {a.data()[0], a.data()[1], a.data()[2]};
}

ArrayD vec_array(const Vec3d& v) {
  ArrayD out(py::ssize_t{3});
  store(out.mutable_data(), v);
  return out;
}

Surface make_surface(double expert_size, double normal_offset, double inside_offset, double blend,
                     double min_sigma, const std::optional<ArrayD>& prior_centre,
                     double prior_radius, double length_scale, double sigma) {
  sh::SurfaceConfig c;
  c.expert_size = expert_size;
  c.normal_offset = normal_offset;
  c.inside_offset = inside_offset;
  c.blend = blend;
  c.min_sigma = min_sigma;
  c.prior_centre = prior_centre ? vec3(*prior_centre, "prior_centre") : Vec3d::Zero();
  c.prior_radius = prior_radius;
  try {
    return Surface(c, sh::Matern32({.length_scale = length_scale, .sigma = sigma}));
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

sh::Grid grid_from(const ArrayD& lo, const ArrayD& hi, double spacing) {
  try {
    return sh::Grid::covering(vec3(lo, "lo"), vec3(hi, "hi"), spacing);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

py::dict mesh_dict(const sh::SurfaceMesh& m) {
  py::array_t<std::uint32_t> tri(
      {static_cast<py::ssize_t>(m.mesh.triangles.size()), py::ssize_t{3}});
  if (!m.mesh.triangles.empty())
    std::memcpy(tri.mutable_data(), m.mesh.triangles.data(), m.mesh.triangles.size() * 3 * 4);
  py::dict d;
  d["vertices"] = points_array(m.mesh.vertices);
  d["triangles"] = tri;
  d["sigma"] = vector_array(m.sigma);
  d["normals"] = points_array(m.normals);
  return d;
}

std::vector<sh::TouchCandidate> candidates_from(const ArrayD& origins, const ArrayD& directions,
                                                double max_distance) {
  const std::vector<Vec3d> o = points_from(origins, "origins");
  const std::vector<Vec3d> d = points_from(directions, "directions");
  if (o.size() != d.size())
    throw py::value_error("origins and directions differ in length (" + std::to_string(o.size()) +
                          " and " + std::to_string(d.size()) + ")");
  if (!(max_distance > 0.0) || !std::isfinite(max_distance))
    throw py::value_error("max_distance must be finite and > 0 [m]");
  std::vector<sh::TouchCandidate> out(o.size());
  for (std::size_t i = 0; i < o.size(); ++i) out[i] = {o[i], d[i], max_distance};
  return out;
}

py::dict predictions_dict(const std::vector<sh::TouchPrediction>& r) {
  const auto n = static_cast<py::ssize_t>(r.size());
  py::array_t<bool> contact(n);
  ArrayD point({n, py::ssize_t{3}}), normal({n, py::ssize_t{3}}), gain(n);
  for (py::ssize_t i = 0; i < n; ++i) {
    const auto& x = r[static_cast<std::size_t>(i)];
    contact.mutable_data()[i] = x.contact;
    store(point.mutable_data() + 3 * i, x.point);
    store(normal.mutable_data() + 3 * i, x.normal);
    gain.mutable_data()[i] = x.gain;
  }
  py::dict out;
  out["contact"] = contact;
  out["point"] = point;
  out["normal"] = normal;
  out["gain"] = gain;
  return out;
}

Explorer make_explorer(const std::optional<ArrayD>& workspace_min,
                       const std::optional<ArrayD>& workspace_max, double grid_spacing,
                       double expert_size, double normal_offset, double inside_offset,
                       double min_sigma, const std::optional<ArrayD>& prior_centre,
                       double prior_radius, bool fit_prior_radius, double length_scale,
                       double sigma, double noise_sigma, double radius, double target_spacing,
                       double free_spacing, double free_threshold, double free_cap) {
  sh::ExplorerConfig c;
  if (workspace_min) c.workspace_min = vec3(*workspace_min, "workspace_min");
  if (workspace_max) c.workspace_max = vec3(*workspace_max, "workspace_max");
  c.grid_spacing = grid_spacing;
  c.surface.expert_size = expert_size;
  c.surface.normal_offset = normal_offset;
  c.surface.inside_offset = inside_offset;
  c.surface.min_sigma = min_sigma;
  c.surface.prior_centre = prior_centre ? vec3(*prior_centre, "prior_centre") : Vec3d::Zero();
  c.surface.prior_radius = prior_radius;
  c.fit_prior_radius = fit_prior_radius;
  c.kernel = {.length_scale = length_scale, .sigma = sigma};
  c.scoring.noise_sigma = noise_sigma;
  c.scoring.radius = radius;
  c.scoring.target_spacing = target_spacing;
  c.free_spacing = free_spacing;
  c.free_threshold = free_threshold;
  c.free_cap = free_cap;
  // A workspace of more than 2^27 grid nodes (1 GiB of field) is a mistake, not a request.
  const Vec3d extent = (c.workspace_max - c.workspace_min) / grid_spacing;
  if (extent.allFinite() && grid_spacing > 0.0 &&
      (extent.array() + 2.0).prod() > double(std::size_t{1} << 27))
    throw py::value_error(
        "Explorer: the workspace holds more than 2^27 grid nodes at "
        "grid_spacing " +
        std::to_string(grid_spacing) + " m");
  try {
    return Explorer(c);
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

/// Doubles in one point state of the Explorer's fused cloud (Surfel's for_each_field).
std::size_t surfel_state_size() {
  std::size_t k = 0;
  fusion::Surfel<double>::State probe{};
  fusion::Surfel<double>::for_each_field(probe, [&](double*, std::size_t len) { k += len; });
  return k;
}

constexpr const char* kExplorerDoc = R"doc(
The loop of exploring an object by touch: contacts are fused (Surfel over VoxelHash), the fused
points feed an implicit surface (see ImplicitSurface; its settings here have the same names),
whose mean is sampled on a grid of `grid_spacing` over the workspace box. estimate() meshes it
with each vertex's standard deviation; score() predicts candidate touches (approach rays) on it
and scores them by the expected drop of the surface's variance over the estimate's vertices
within `radius` of each contact. With fit_prior_radius the prior sphere's radius follows the
points' mean distance from prior_centre. add_free_space() tells it where a finger moved without
touching. Lengths in metres. Calls from several threads run one at a time and release the GIL.
Pickles whole: fused cloud, surface and settings.)doc";

/// The pickled state of an ImplicitSurface (the caller holds its lock).
py::tuple surface_state(const Surface& s) {
  const sh::SurfaceConfig& c = s.config();
  const std::size_t n = s.id_count();
  std::vector<Vec3d> pos(n), nor(n);
  std::vector<double> var(n), val(n);
  std::vector<std::uint8_t> alive(n), free(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& p = s.point(i);
    pos[i] = p.position;
    nor[i] = p.normal;
    var[i] = p.variance;
    val[i] = p.value;
    alive[i] = p.alive;
    free[i] = p.free;
  }
  return py::make_tuple(c.expert_size, c.normal_offset, c.blend, c.min_sigma,
                        vec_array(c.prior_centre), c.prior_radius, s.kernel().config().length_scale,
                        s.kernel().config().sigma, points_array(pos), points_array(nor),
                        vector_array(var), vector_array(val), vector_array(alive),
                        vector_array(free), c.inside_offset);
}

/// An ImplicitSurface from surface_state().
Surface surface_from_state(const py::tuple& a) {
  // 14 items: pickled before inside_offset existed, when it was normal_offset.
  if (a.size() != 14 && a.size() != 15)
    throw py::value_error("ImplicitSurface: damaged pickled state");
  const double inside = a.size() == 15 ? a[14].cast<double>() : a[1].cast<double>();
  Surface s = make_surface(a[0].cast<double>(), a[1].cast<double>(), inside, a[2].cast<double>(),
                           a[3].cast<double>(), a[4].cast<ArrayD>(), a[5].cast<double>(),
                           a[6].cast<double>(), a[7].cast<double>());
  const std::vector<Vec3d> pos = points_from(a[8].cast<ArrayD>(), "positions");
  const std::vector<Vec3d> nor = points_from(a[9].cast<ArrayD>(), "normals");
  const auto var = a[10].cast<std::vector<double>>();
  const auto val = a[11].cast<std::vector<double>>();
  const auto alive = a[12].cast<std::vector<std::uint8_t>>();
  const auto free = a[13].cast<std::vector<std::uint8_t>>();
  if (nor.size() != pos.size() || var.size() != pos.size() || val.size() != pos.size() ||
      alive.size() != pos.size() || free.size() != pos.size())
    throw py::value_error("ImplicitSurface: damaged pickled state");
  for (std::size_t i = 0; i < pos.size(); ++i) {
    // Erased points are added and erased again, so that every id keeps its point.
    const auto id = free[i] ? s.insert_free(pos[i], val[i], var[i])
                            : s.insert(pos[i], nor[i].norm() > 0 ? nor[i] : Vec3d::UnitZ(), var[i]);
    if (!id || *id != i) throw py::value_error("ImplicitSurface: damaged pickled state");
    if (!alive[i]) s.erase(i);
  }
  return s;
}

constexpr const char* kSurfaceDoc = R"doc(
A Gaussian-process implicit surface over local experts: a field f, negative inside, zero on
the surface, positive outside, about the signed distance near it, with a posterior variance
everywhere. Each surface point observes f = 0 there, f = d at d along its normal and
f = -d_in at d_in against it (d = normal_offset, d_in = inside_offset; 0 leaves one out);
free-space points observe a positive value. The prior mean is the signed
distance to the sphere (prior_centre, prior_radius); the kernel is Matern 3/2 with length_scale
and sigma (scikit-learn's ConstantKernel(sigma**2) * Matern(length_scale, nu=1.5)). Experts of
side expert_size each keep an exact process of the points within half a side of their cube;
adding or moving a point updates 8 of them by rank-one steps, never a refit. Lengths in metres.
Calls from several threads run one at a time (queries together) and release the GIL.)doc";

}  // namespace

void bind_shape(py::module_& root) {
  py::module_ m = root.def_submodule("shape", R"doc(
Shape with uncertainty: a Gaussian-process implicit surface built from fused points (their
normals and variances), queried for mean, variance and gradient, meshed with each vertex's
standard deviation, and candidate touches (approach rays) scored by the expected drop of the
surface's variance. Lengths in metres.)doc");

  py::class_<Surface> cls(m, "ImplicitSurface", kSurfaceDoc);
  pickle_with(
      cls, "ImplicitSurface",
      [](const Surface& s) {
        const auto lock = read_lock(&s);
        return surface_state(s);
      },
      [](const py::tuple& a) { return surface_from_state(a); });
  cls.def(py::init(&make_surface), py::kw_only(), py::arg("expert_size") = 0.015,
          py::arg("normal_offset") = 0.003, py::arg("inside_offset") = 0.003,
          py::arg("blend") = 0.1, py::arg("min_sigma") = 0.2e-3,
          py::arg("prior_centre") = py::none(), py::arg("prior_radius") = 0.0,
          py::arg("length_scale") = 0.02, py::arg("sigma") = 0.01,
          "An empty surface (prior_centre None: the origin); ValueError naming a setting out "
          "of range.")
      .def("__len__",
           [](const Surface& s) {
             const auto lock = read_lock(&s);
             return s.size();
           })
      .def("__repr__",
           [](const Surface& s) {
             const auto lock = read_lock(&s);
             char text[200];
             std::snprintf(text, sizeof text,
                           "ImplicitSurface(%zu points, %zu experts, expert_size=%g, "
                           "length_scale=%g, prior_radius=%g)",
                           s.size(), s.expert_count(), s.config().expert_size,
                           s.kernel().config().length_scale, s.config().prior_radius);
             return std::string(text);
           })
      .def_property_readonly(
          "expert_count",
          [](const Surface& s) {
            const auto lock = read_lock(&s);
            return s.expert_count();
          },
          "number of experts")
      .def_property_readonly(
          "prior_centre",
          [](const Surface& s) {
            const auto lock = read_lock(&s);
            return vec_array(s.config().prior_centre);
          },
          "centre of the prior sphere [m]")
      .def_property_readonly(
          "prior_radius",
          [](const Surface& s) {
            const auto lock = read_lock(&s);
            return s.config().prior_radius;
          },
          "radius of the prior sphere [m]")
      .def(
          "insert",
          [](Surface& s, const ArrayD& points, const ArrayD& normals,
             const std::optional<ArrayD>& variances) {
            const std::vector<Vec3d> p = points_from(points, "points");
            const std::vector<Vec3d> n = points_from(normals, "normals");
            if (n.size() != p.size())
              throw py::value_error("insert: points and normals differ in length");
            std::vector<double> v(p.size(), 0.0);
            if (variances) {
              require_shape(*variances, {static_cast<py::ssize_t>(p.size())}, "variances", "(N,)");
              std::memcpy(v.data(), variances->data(), v.size() * sizeof(double));
            }
            py::array_t<std::int64_t> ids(static_cast<py::ssize_t>(p.size()));
            std::int64_t* out = ids.mutable_data();
            py::gil_scoped_release release;
            const auto lock = write_lock(&s);
            for (std::size_t i = 0; i < p.size(); ++i) {
              const auto id = s.insert(p[i], n[i], v[i]);
              out[i] = id ? static_cast<std::int64_t>(*id) : -1;
            }
            return ids;
          },
          py::arg("points"), py::arg("normals"), py::arg("variances") = py::none(),
          "Adds (N, 3) surface points with (N, 3) outward normals and (N,) variances along "
          "them [m^2] (default 0: the min_sigma floor). Returns their ids (int64), -1 for a "
          "point refused (not finite, a zero normal, a negative variance).")
      .def(
          "insert_free",
          [](Surface& s, const ArrayD& points, double value, double variance) {
            const std::vector<Vec3d> p = points_from(points, "points");
            py::array_t<std::int64_t> ids(static_cast<py::ssize_t>(p.size()));
            std::int64_t* out = ids.mutable_data();
            py::gil_scoped_release release;
            const auto lock = write_lock(&s);
            for (std::size_t i = 0; i < p.size(); ++i) {
              const auto id = s.insert_free(p[i], value, variance);
              out[i] = id ? static_cast<std::int64_t>(*id) : -1;
            }
            return ids;
          },
          py::arg("points"), py::arg("value"), py::arg("variance"),
          "Adds (N, 3) free-space points, each observing the field's value `value` (> 0: "
          "outside) with noise variance `variance`. Returns their ids, -1 where refused.")
      .def(
          "update",
          [](Surface& s, std::size_t id, const ArrayD& point, const ArrayD& normal,
             double variance) {
            const Vec3d p = vec3(point, "point"), n = vec3(normal, "normal");
            py::gil_scoped_release release;
            const auto lock = write_lock(&s);
            try {
              return s.update(id, p, n, variance);
            } catch (const std::out_of_range& e) {
              throw py::index_error(e.what());
            }
          },
          py::arg("id"), py::arg("point"), py::arg("normal"), py::arg("variance") = 0.0,
          "Moves surface point `id` (a fused point that moved); False, and nothing changed, "
          "for an invalid input or a free-space point; IndexError for an unknown id.")
      .def(
          "erase",
          [](Surface& s, std::size_t id) {
            py::gil_scoped_release release;
            const auto lock = write_lock(&s);
            try {
              s.erase(id);
            } catch (const std::out_of_range& e) {
              throw py::index_error(e.what());
            }
          },
          py::arg("id"), "Removes point `id`; IndexError for an unknown or erased id.")
      .def(
          "set_prior",
          [](Surface& s, const ArrayD& centre, double radius) {
            const Vec3d c = vec3(centre, "centre");
            py::gil_scoped_release release;
            const auto lock = write_lock(&s);
            try {
              s.set_prior(c, radius);
            } catch (const std::invalid_argument& e) {
              throw py::value_error(e.what());
            }
          },
          py::arg("centre"), py::arg("radius"),
          "Replaces the prior sphere; ValueError for a non-finite centre or a negative radius.")
      .def(
          "predict",
          [](const Surface& s, const ArrayD& points) {
            const std::vector<Vec3d> p = points_from(points, "points");
            const auto n = static_cast<py::ssize_t>(p.size());
            ArrayD mean(n), var(n), grad({n, py::ssize_t{3}});
            double* mo = mean.mutable_data();
            double* vo = var.mutable_data();
            double* go = grad.mutable_data();
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&s);
              Eigen::Matrix3Xd q(3, n);
              for (py::ssize_t i = 0; i < n; ++i) q.col(i) = p[static_cast<std::size_t>(i)];
              s.evaluate(q, mo, vo);
              for (py::ssize_t i = 0; i < n; ++i) {
                Vec3d g = Vec3d::Zero();
                (void)s.mean(p[static_cast<std::size_t>(i)], g);
                store(go + 3 * i, g);
              }
            }
            return py::make_tuple(mean, var, grad);
          },
          py::arg("points"),
          "The field at (N, 3) points: (mean (N,), variance (N,), gradient of the mean (N, 3)).")
      .def(
          "mean",
          [](const Surface& s, const ArrayD& points) {
            const std::vector<Vec3d> p = points_from(points, "points");
            const auto n = static_cast<py::ssize_t>(p.size());
            ArrayD mean(n);
            double* mo = mean.mutable_data();
            py::gil_scoped_release release;
            const auto lock = read_lock(&s);
            for (py::ssize_t i = 0; i < n; ++i) mo[i] = s.mean(p[static_cast<std::size_t>(i)]);
            return mean;
          },
          py::arg("points"), "The posterior mean of the field at (N, 3) points, (N,).")
      .def(
          "mesh",
          [](const Surface& s, const ArrayD& lo, const ArrayD& hi, double spacing) {
            const sh::Grid g = grid_from(lo, hi, spacing);
            sh::SurfaceMesh mesh;
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&s);
              mesh = sh::extract_surface(s, g);
            }
            return mesh_dict(mesh);
          },
          py::arg("lo"), py::arg("hi"), py::arg("spacing"),
          "The zero level set of the mean on a grid of `spacing` over the box [lo, hi], closed "
          "at the box: a dict with vertices (V, 3), triangles (T, 3) uint32 (counter-clockwise "
          "seen from outside), sigma (V,) [m] and normals (V, 3).")
      .def(
          "score_touches",
          [](const Surface& s, const ArrayD& origins, const ArrayD& directions,
             const ArrayD& targets, const ArrayD& lo, const ArrayD& hi, double spacing,
             double max_distance, double noise_sigma, double radius, int patch_points,
             double patch_radius, double target_spacing) {
            const std::vector<sh::TouchCandidate> cands =
                candidates_from(origins, directions, max_distance);
            const std::vector<Vec3d> t = points_from(targets, "targets");
            const sh::Grid g = grid_from(lo, hi, spacing);
            std::vector<sh::TouchPrediction> r;
            try {
              py::gil_scoped_release release;
              const auto lock = read_lock(&s);
              r = sh::score_touches(
                  s, g, s.sample(g), t, cands,
                  {noise_sigma, radius, patch_points, patch_radius, target_spacing});
            } catch (const std::invalid_argument& e) {
              throw py::value_error(e.what());
            }
            return predictions_dict(r);
          },
          py::arg("origins"), py::arg("directions"), py::arg("targets"), py::arg("lo"),
          py::arg("hi"), py::kw_only(), py::arg("spacing") = 3e-3, py::arg("max_distance") = 0.5,
          py::arg("noise_sigma") = 0.3e-3, py::arg("radius") = 0.012, py::arg("patch_points") = 0,
          py::arg("patch_radius") = 3e-3, py::arg("target_spacing") = 4e-3,
          "Predicts and scores candidate touches, approach rays from (N, 3) origins along (N, 3) "
          "directions: each contact is where the ray first crosses the mean's zero level "
          "(sampled at `spacing` over [lo, hi]); its gain the expected drop of the variance "
          "summed over the (M, 3) targets within `radius` of it. A dict with contact (N,) bool, "
          "point (N, 3), normal (N, 3) and gain (N,) [m^2].");

  m.def(
      "approach_rays",
      [](const ArrayD& centre, double standoff, double aim_radius, int count, std::uint64_t seed) {
        const Vec3d c = vec3(centre, "centre");
        std::mt19937_64 rng(seed);
        std::vector<sh::TouchCandidate> r;
        try {
          r = sh::approach_rays(c, standoff, aim_radius, count, rng);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        std::vector<Vec3d> o, d;
        for (const auto& x : r) {
          o.push_back(x.origin);
          d.push_back(x.direction);
        }
        return py::make_tuple(points_array(o), points_array(d));
      },
      py::arg("centre"), py::arg("standoff"), py::arg("aim_radius"), py::arg("count"),
      py::kw_only(), py::arg("seed") = 1,
      "`count` random approach rays: (origins (N, 3), unit directions (N, 3)), each from the "
      "sphere of radius `standoff` around `centre` towards a random point within `aim_radius` "
      "of it. Deterministic for a seed.");

  m.def(
      "marching_tetrahedra",
      [](const py::array_t<double, py::array::f_style | py::array::forcecast>& values,
         const ArrayD& origin, double spacing, double level, bool close) {
        if (values.ndim() != 3)
          throw py::value_error("marching_tetrahedra: values must be a 3-D array (nx, ny, nz)");
        sh::Grid g;
        g.origin = vec3(origin, "origin");
        g.spacing = spacing;
        g.nodes = {static_cast<int>(values.shape(0)), static_cast<int>(values.shape(1)),
                   static_cast<int>(values.shape(2))};
        std::vector<double> v(values.data(), values.data() + values.size());
        sh::Mesh mesh;
        try {
          py::gil_scoped_release release;
          mesh = sh::marching_tetrahedra(g, v, level, close);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        py::array_t<std::uint32_t> tri(
            {static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
        if (!mesh.triangles.empty())
          std::memcpy(tri.mutable_data(), mesh.triangles.data(), mesh.triangles.size() * 3 * 4);
        return py::make_tuple(points_array(mesh.vertices), tri);
      },
      py::arg("values"), py::arg("origin"), py::arg("spacing"), py::kw_only(),
      py::arg("level") = 0.0, py::arg("close") = false,
      "The surface where a field sampled on a grid, values[i, j, k] at origin + spacing * (i, "
      "j, k), crosses `level`, by marching tetrahedra: (vertices (V, 3), triangles (T, 3) "
      "uint32), counter-clockwise seen from above the level. `close` counts the grid's border "
      "as above the level, closing the mesh.");

  py::class_<Explorer> ex(m, "Explorer", kExplorerDoc);
  pickle_with(
      ex, "Explorer",
      [](const Explorer& e) {
        const auto lock = read_lock(&e);
        const sh::ExplorerConfig& c = e.config();
        const py::tuple settings =
            py::make_tuple(vec_array(c.workspace_min), vec_array(c.workspace_max), c.grid_spacing,
                           c.surface.expert_size, c.surface.normal_offset, c.surface.inside_offset,
                           c.surface.min_sigma, vec_array(c.surface.prior_centre),
                           c.surface.prior_radius, c.fit_prior_radius, c.kernel.length_scale,
                           c.kernel.sigma, c.scoring.noise_sigma, c.scoring.radius,
                           c.scoring.target_spacing, c.free_spacing, c.free_threshold, c.free_cap);
        using F = fusion::Surfel<double>;
        const std::size_t k = surfel_state_size();
        const auto n = static_cast<py::ssize_t>(e.cloud().size());
        ArrayD states({n, static_cast<py::ssize_t>(k)}), times(n);
        py::array_t<std::uint32_t> obs(n);
        py::array_t<std::int64_t> ids(n);
        double* out = states.mutable_data();
        for (py::ssize_t i = 0; i < n; ++i) {
          const auto id = static_cast<index::PointId>(i);
          F::State st = e.cloud().state(id);
          F::for_each_field(st, [&](const double* v, std::size_t len) {
            std::copy(v, v + len, out);
            out += len;
          });
          obs.mutable_data()[i] = e.cloud().observations(id);
          times.mutable_data()[i] = e.cloud().last_time(id);
          const auto sid = e.surface_id(id);
          ids.mutable_data()[i] = sid ? static_cast<std::int64_t>(*sid) : -1;
        }
        return py::make_tuple(settings, states, obs, times, surface_state(e.surface()), ids);
      },
      [](const py::tuple& a) {
        if (a.size() != 6) throw py::value_error("Explorer: damaged pickled state");
        const auto t = a[0].cast<py::tuple>();
        if (t.size() != 18) throw py::value_error("Explorer: damaged pickled settings");
        const Explorer fresh = make_explorer(
            t[0].cast<ArrayD>(), t[1].cast<ArrayD>(), t[2].cast<double>(), t[3].cast<double>(),
            t[4].cast<double>(), t[5].cast<double>(), t[6].cast<double>(), t[7].cast<ArrayD>(),
            t[8].cast<double>(), t[9].cast<bool>(), t[10].cast<double>(), t[11].cast<double>(),
            t[12].cast<double>(), t[13].cast<double>(), t[14].cast<double>(), t[15].cast<double>(),
            t[16].cast<double>(), t[17].cast<double>());
        using F = fusion::Surfel<double>;
        const std::size_t k = surfel_state_size();
        const auto states = a[1].cast<ArrayD>();
        const auto obs = a[2].cast<StrictArray<std::uint32_t>>();
        const auto times = a[3].cast<ArrayD>();
        const auto ids = a[5].cast<StrictArray<std::int64_t>>();
        require_shape(states, {-1, static_cast<py::ssize_t>(k)}, "pickled states",
                      "(N, state size)");
        require_shape(obs, {states.shape(0)}, "pickled observations", "(N,)");
        require_shape(times, {states.shape(0)}, "pickled times", "(N,)");
        require_shape(ids, {states.shape(0)}, "pickled surface ids", "(N,)");
        Explorer::CloudType cloud(fresh.cloud().config());
        std::vector<std::optional<std::size_t>> of_cloud(static_cast<std::size_t>(ids.size()));
        try {
          for (py::ssize_t i = 0; i < states.shape(0); ++i) {
            F::State st{};
            const double* in = states.data() + i * static_cast<py::ssize_t>(k);
            F::for_each_field(st, [&](double* v, std::size_t len) {
              std::copy(in, in + len, v);
              in += len;
            });
            (void)cloud.restore(st, obs.data()[i], times.data()[i]);
            if (ids.data()[i] >= 0)
              of_cloud[static_cast<std::size_t>(i)] = static_cast<std::size_t>(ids.data()[i]);
          }
          return Explorer(fresh.config(), std::move(cloud),
                          surface_from_state(a[4].cast<py::tuple>()), std::move(of_cloud));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("Explorer: damaged pickled state: ") + e.what());
        }
      });
  ex.def(py::init(&make_explorer), py::kw_only(), py::arg("workspace_min") = py::none(),
         py::arg("workspace_max") = py::none(), py::arg("grid_spacing") = 2e-3,
         py::arg("expert_size") = 0.015, py::arg("normal_offset") = 0.003,
         py::arg("inside_offset") = 0.003, py::arg("min_sigma") = 0.2e-3,
         py::arg("prior_centre") = py::none(), py::arg("prior_radius") = 0.0,
         py::arg("fit_prior_radius") = true, py::arg("length_scale") = 0.02,
         py::arg("sigma") = 0.01, py::arg("noise_sigma") = 0.3e-3, py::arg("radius") = 0.012,
         py::arg("target_spacing") = 4e-3, py::arg("free_spacing") = 5e-3,
         py::arg("free_threshold") = 5e-3, py::arg("free_cap") = 3e-3,
         "An explorer with nothing touched yet; the workspace box defaults to +-60 mm around the "
         "origin. ValueError naming a setting out of range.")
      .def("__len__",
           [](const Explorer& e) {
             const auto lock = read_lock(&e);
             return e.cloud().size();
           })
      .def("__repr__",
           [](const Explorer& e) {
             const auto lock = read_lock(&e);
             char text[200];
             std::snprintf(text, sizeof text,
                           "Explorer(%zu fused points, %zu surface points, prior_radius=%g)",
                           e.cloud().size(), e.surface().size(), e.surface().config().prior_radius);
             return std::string(text);
           })
      .def(
          "add_contacts",
          [](Explorer& e, ArrayD positions, std::optional<ArrayD> covariances,
             std::optional<ArrayD> normals, std::optional<double> sigma) {
            const ContactRows rows =
                contact_rows(std::move(positions), std::move(covariances), std::move(normals),
                             std::nullopt, std::nullopt, sigma, 0.0);
            std::vector<Contact<double>> cs(rows.n);
            for (std::size_t i = 0; i < rows.n; ++i) {
              cs[i] = rows.at(i);
              const ContactDefect d = e.cloud().defect(cs[i]);
              if (d != ContactDefect::ok)
                throw py::value_error("contact " + std::to_string(i) + ": " +
                                      std::string(to_string(d)) + " (nothing was added)");
            }
            py::gil_scoped_release release;
            const auto lock = write_lock(&e);
            return e.add_contacts(cs);
          },
          py::arg("positions"), py::arg("covariances") = py::none(),
          py::arg("normals") = py::none(), py::kw_only(), py::arg("sigma") = py::none(),
          "Fuses contacts (the arrays of ContactCloud.insert: positions (N, 3), covariances (N, "
          "3, 3) or one (3, 3), or an isotropic `sigma`; normals (N, 3)) and brings the surface "
          "up to date. Returns how many fused points were added or moved. ValueError for an "
          "invalid contact, and nothing is added.")
      .def(
          "add_contacts",
          [](Explorer& e, const ContactList& contacts) {
            py::gil_scoped_release release;
            const auto lock = write_lock(&e);
            return e.add_contacts(contacts);
          },
          py::arg("contacts"),
          "Fuses a taxel.Contacts (invalid contacts are skipped). Returns how many fused points "
          "were added or moved.")
      .def(
          "add_free_space",
          [](Explorer& e, const ArrayD& start, const ArrayD& end) {
            const Vec3d a = vec3(start, "start"), b = vec3(end, "end");
            py::gil_scoped_release release;
            const auto lock = write_lock(&e);
            return e.add_free_space(a, b);
          },
          py::arg("start"), py::arg("end"),
          "Tells the surface that the segment from `start` to `end` is free (a finger moved "
          "through it); points every free_spacing where the estimate puts the surface near or "
          "beyond them observe a positive field. Returns how many were added.")
      .def(
          "estimate",
          [](Explorer& e) {
            sh::SurfaceMesh mesh;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&e);
              mesh = e.estimate();
            }
            return mesh_dict(mesh);
          },
          "The estimated surface: a dict with vertices (V, 3), triangles (T, 3) uint32, sigma "
          "(V,) [m] and normals (V, 3) (see ImplicitSurface.mesh).")
      .def(
          "field",
          [](Explorer& e) {
            py::array_t<double, py::array::f_style> out;
            const sh::Grid& g = e.grid();
            out = py::array_t<double, py::array::f_style>(
                {py::ssize_t{g.nodes[0]}, py::ssize_t{g.nodes[1]}, py::ssize_t{g.nodes[2]}});
            double* dst = out.mutable_data();
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&e);
              const std::vector<double>& f = e.field();
              std::copy(f.begin(), f.end(), dst);
            }
            return out;
          },
          "The posterior mean on the grid, (nx, ny, nz): entry [i, j, k] at grid_origin + "
          "grid_spacing * (i, j, k) (marching_tetrahedra's layout).")
      .def_property_readonly(
          "grid_origin", [](const Explorer& e) { return vec_array(e.grid().origin); },
          "the grid's first node [m]")
      .def_property_readonly(
          "grid_spacing", [](const Explorer& e) { return e.grid().spacing; },
          "the grid's spacing [m]")
      .def_property_readonly(
          "prior_radius",
          [](const Explorer& e) {
            const auto lock = read_lock(&e);
            return e.surface().config().prior_radius;
          },
          "radius of the prior sphere now [m]")
      .def_property_readonly(
          "points",
          [](const Explorer& e) {
            const auto lock = read_lock(&e);
            std::vector<Vec3d> p(e.cloud().size());
            for (std::size_t i = 0; i < p.size(); ++i)
              p[i] = e.cloud().mean(static_cast<index::PointId>(i));
            return points_array(p);
          },
          "(M, 3) fused point positions [m], in id order")
      .def(
          "predict",
          [](const Explorer& e, const ArrayD& points) {
            const std::vector<Vec3d> p = points_from(points, "points");
            const auto n = static_cast<py::ssize_t>(p.size());
            ArrayD mean(n), var(n);
            double* mo = mean.mutable_data();
            double* vo = var.mutable_data();
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&e);
              Eigen::Matrix3Xd q(3, n);
              for (py::ssize_t i = 0; i < n; ++i) q.col(i) = p[static_cast<std::size_t>(i)];
              e.surface().evaluate(q, mo, vo);
            }
            return py::make_tuple(mean, var);
          },
          py::arg("points"), "The surface's field at (N, 3) points: (mean (N,), variance (N,)).")
      .def(
          "score",
          [](Explorer& e, const ArrayD& origins, const ArrayD& directions, double max_distance) {
            const std::vector<sh::TouchCandidate> cands =
                candidates_from(origins, directions, max_distance);
            std::vector<sh::TouchPrediction> r;
            {
              py::gil_scoped_release release;
              const auto lock = write_lock(&e);
              r = e.score(cands);
            }
            return predictions_dict(r);
          },
          py::arg("origins"), py::arg("directions"), py::kw_only(), py::arg("max_distance") = 0.5,
          "Predicts and scores candidate touches, approach rays from (N, 3) origins along (N, 3) "
          "directions up to max_distance: a dict with contact (N,) bool, point (N, 3), normal "
          "(N, 3) and gain (N,) [m^2] (see ImplicitSurface.score_touches). The best touch is "
          "the contact with the largest gain.");

  py::class_<sh::Hypothesis> hyp(m, "Hypothesis",
                                 "One hypothesis of a recognition belief: a model at a pose.");
  hyp.def(py::init([](std::string name, std::size_t model, const ArrayD& model_from_world,
                      double score, double probability) {
            return sh::Hypothesis{std::move(name), model,
                                  pose_from(model_from_world, "model_from_world"), score,
                                  probability};
          }),
          py::kw_only(), py::arg("name"), py::arg("model"), py::arg("model_from_world"),
          py::arg("score") = 0.0, py::arg("probability"),
          "A hypothesis; ValueError unless model_from_world is a rigid (4, 4) transform.")
      .def_readonly("name", &sh::Hypothesis::name, "the model's name")
      .def_readonly("model", &sh::Hypothesis::model, "the model's index in the library")
      .def_property_readonly(
          "model_from_world",
          [](const sh::Hypothesis& h) { return pose_array(h.model_from_world); },
          "(4, 4) transform from the world (the cloud's frame) into the model's")
      .def_readonly("score", &sh::Hypothesis::score, "the fit's truncated RMS distance [m]")
      .def_readonly("probability", &sh::Hypothesis::probability, "its probability")
      .def("__repr__", [](const sh::Hypothesis& h) {
        char text[160];
        std::snprintf(text, sizeof text, "Hypothesis(%.60s, probability=%.4g, score=%.4g m)",
                      h.name.c_str(), h.probability, h.score);
        return std::string(text);
      });
  pickle_members(hyp, "Hypothesis", &sh::Hypothesis::name, &sh::Hypothesis::model,
                 &sh::Hypothesis::model_from_world, &sh::Hypothesis::score,
                 &sh::Hypothesis::probability);

  m.def(
      "hypotheses",
      [](const registration::ObjectRecognition& r, std::size_t points, double sigma,
         std::size_t max_points) {
        sh::BeliefConfig c;
        c.sigma = sigma;
        c.max_points = max_points;
        try {
          return sh::hypotheses(r, points, c);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("recognition"), py::arg("points"), py::kw_only(), py::arg("sigma") = 1e-3,
      py::arg("max_points") = 50,
      "The belief over (model, pose) of an ObjectLibrary.recognize() result for a cloud of "
      "`points` points, most probable first: p ~ exp(-n score^2 / (2 sigma^2)), n = min(points, "
      "max_points). Empty for a failed recognition.");

  m.def(
      "score_recognition_touches",
      [](const registration::ObjectLibrary<double>& library,
         const std::vector<sh::Hypothesis>& belief, const ArrayD& origins, const ArrayD& directions,
         double max_distance, double ray_sigma, double surface_tolerance, double confusion,
         std::size_t hypotheses) {
        const std::vector<sh::TouchCandidate> cands =
            candidates_from(origins, directions, max_distance);
        sh::BeliefConfig c;
        c.ray_sigma = ray_sigma;
        c.surface_tolerance = surface_tolerance;
        c.confusion = confusion;
        c.hypotheses = hypotheses;
        std::vector<double> gain;
        try {
          py::gil_scoped_release release;
          const auto lock = read_lock(&library);
          gain = sh::score_recognition_touches(library, belief, cands, c);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
        return vector_array(gain);
      },
      py::arg("library"), py::arg("belief"), py::arg("origins"), py::arg("directions"),
      py::kw_only(), py::arg("max_distance") = 0.5, py::arg("ray_sigma") = 2e-3,
      py::arg("surface_tolerance") = 1.5e-3, py::arg("confusion") = 1e-3, py::arg("hypotheses") = 6,
      "The expected drop of the belief's entropy [nats] for each candidate touch (approach rays "
      "from (N, 3) origins along (N, 3) directions), over its `hypotheses` most probable "
      "entries: each ray is cast against each model at its pose, and a touch scores high when "
      "the likely models disagree on where (or whether) it meets the object.");
}

}  // namespace taxel::python
