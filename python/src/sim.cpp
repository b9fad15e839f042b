// SPDX-License-Identifier: MIT
// taxel.sim: shapes, surface sampling, simulated explorations with a tactile pad, surface
// errors and the palm-grasp image synthesiser.
#include <variant>

#include "common.hpp"
#include "taxel/sim.hpp"

namespace taxel::python {
namespace {

namespace sm = taxel::sim;

template <class Sh, class Fn>
ArrayD per_point(const Sh& shape, const ArrayD& points, Fn&& fn, int width) {
  require_shape(points, {-1, 3}, "points", "(N, 3)");
  const py::ssize_t n = points.shape(0);
  ArrayD out = width == 1 ? ArrayD(n) : ArrayD({n, py::ssize_t{3}});
  const double* p = points.data();
  double* o = out.mutable_data();
  py::gil_scoped_release release;
  for (py::ssize_t i = 0; i < n; ++i)
    fn(shape, Vec3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]), o + i * width);
  return out;
}

/// Methods every shape has.
template <class Sh>
void shape_methods(py::class_<Sh>& cls) {
  cls.def(
         "signed_distance",
         [](const Sh& s, const ArrayD& points) {
           return per_point(
               s, points,
               [](const Sh& sh, const Vec3d& p, double* o) { *o = sh.signed_distance(p); }, 1);
         },
         py::arg("points"), "(N,) signed distances [m] of (N, 3) points, outside positive")
      .def(
          "closest_point",
          [](const Sh& s, const ArrayD& points) {
            return per_point(
                s, points,
                [](const Sh& sh, const Vec3d& p, double* o) {
                  store(o, Vec3d(sh.closest_point(p)));
                },
                3);
          },
          py::arg("points"), "(N, 3) closest surface points")
      .def(
          "normal",
          [](const Sh& s, const ArrayD& points) {
            return per_point(
                s, points,
                [](const Sh& sh, const Vec3d& p, double* o) { store(o, Vec3d(sh.normal(p))); }, 3);
          },
          py::arg("points"), "(N, 3) outward unit normals at the closest surface points")
      .def(
          "surface_area", [](const Sh& s) { return sm::surface_area(s); }, "[m^2]")
      .def(
          "sample_surface",
          [](const Sh& s, std::size_t count, std::uint64_t seed) {
            py::gil_scoped_release release;
            return sm::sample_surface(s, count, seed);
          },
          py::arg("count"), py::arg("seed") = 1,
          "A PointCloud of `count` area-uniform surface points with their normals")
      .def(
          "sample_surface_spacing",
          [](const Sh& s, double spacing, std::uint64_t seed, std::size_t max_points) {
            py::gil_scoped_release release;
            return sm::sample_surface_spacing(s, spacing, seed, max_points);
          },
          py::arg("spacing"), py::arg("seed") = 1, py::arg("max_points") = std::size_t{1} << 22,
          "About one surface point per spacing^2 [m]");
}

using AnyShape = std::variant<sm::Sphere, sm::Cylinder, sm::Box, sm::Cone, sm::Ellipsoid, sm::Torus,
                              sm::TriangleMesh>;

AnyShape shape_from(const py::object& obj) {
  if (py::isinstance<sm::Sphere>(obj)) return obj.cast<sm::Sphere>();
  if (py::isinstance<sm::Cylinder>(obj)) return obj.cast<sm::Cylinder>();
  if (py::isinstance<sm::Box>(obj)) return obj.cast<sm::Box>();
  if (py::isinstance<sm::Cone>(obj)) return obj.cast<sm::Cone>();
  if (py::isinstance<sm::Ellipsoid>(obj)) return obj.cast<sm::Ellipsoid>();
  if (py::isinstance<sm::Torus>(obj)) return obj.cast<sm::Torus>();
  if (py::isinstance<sm::TriangleMesh>(obj)) return obj.cast<sm::TriangleMesh>();
  throw py::type_error("expected a taxel.sim shape, got " +
                       std::string(py::str(py::type::of(obj))));
}

/// A simulated exploration: frames of pad readings, poses and the contacts they gave.
struct PyExploration {
  std::vector<sm::ExplorationFrame> frames;
  Isometry3d object_pose;
};

sm::ExplorationConfig exploration_config(const sensor::SensorModel& sensor,
                                         const sensor::ContactOptions& contacts, double frame_rate,
                                         double indentation, const std::optional<ArrayD>& pose,
                                         std::uint64_t seed) {
  sm::ExplorationConfig c;
  c.sensor = sensor;
  c.contacts = contacts;
  c.frame_rate = frame_rate;
  c.indentation = indentation;
  c.object_pose = pose ? pose_from(*pose, "object_pose") : Isometry3d::Identity();
  c.seed = seed;
  return c;
}

template <class Explore>
PyExploration explore(const py::object& shape, const sm::ExplorationConfig& cfg, Explore&& fn) {
  const AnyShape s = shape_from(shape);
  py::gil_scoped_release release;
  return std::visit(
      [&](const auto& sh) {
        auto ex = fn(sh, cfg);
        return PyExploration{std::move(ex.frames), cfg.object_pose};
      },
      s);
}

/// The largest pad count of any frame, or ValueError when frames differ.
std::size_t pads_per_frame(const PyExploration& e) {
  std::size_t pads = e.frames.empty() ? 0 : e.frames.front().pads.size();
  for (const auto& f : e.frames) {
    if (f.pads.size() != pads) {
      throw py::value_error("the frames use different numbers of pads");
    }
  }
  return pads;
}

#define TAXEL_EXPLORATION_ARGS                                                               \
  py::arg("sensor") = sensor::SensorModel{}, py::arg("contacts") = sensor::ContactOptions{}, \
  py::arg("frame_rate") = 1000.0, py::arg("indentation") = 1e-3,                             \
  py::arg("object_pose") = py::none(), py::arg("seed") = 1

}  // namespace

void bind_sim(py::module_& root) {
  py::module_ m = root.def_submodule("sim", R"doc(
Simulation: analytic shapes and triangle meshes (metres, centred at the origin), surface
sampling, tactile explorations with a pad of the sensor model, surface errors, and the
palm-grasp pressure-image synthesiser.)doc");

  py::class_<sm::Sphere> sphere(m, "Sphere", "Sphere of `radius` [m] centred at the origin.");
  sphere.def(py::init<double>(), py::arg("radius") = 0.04)
      .def_readonly("radius", &sm::Sphere::radius, "radius [m]");
  shape_methods(sphere);
  py::class_<sm::Cylinder> cylinder(m, "Cylinder", "Capped cylinder along z.");
  cylinder.def(py::init<double, double>(), py::arg("radius") = 0.03, py::arg("half_height") = 0.05)
      .def_readonly("radius", &sm::Cylinder::radius, "radius [m]")
      .def_readonly("half_height", &sm::Cylinder::half_height, "half of the height [m]");
  shape_methods(cylinder);
  py::class_<sm::Box> box(m, "Box",
                          "Box of `half_extents` [m] centred at the origin, axis-aligned.");
  box.def(py::init([](const Eigen::Vector3d& h) { return sm::Box(h); }),
          py::arg("half_extents") = Eigen::Vector3d(0.04, 0.03, 0.02))
      .def_readonly("half_extents", &sm::Box::half_extents, "half side lengths along x, y, z [m]");
  shape_methods(box);
  py::class_<sm::Cone> cone(m, "Cone", "Cone along z, base radius and height.");
  cone.def(py::init<double, double>(), py::arg("radius") = 0.03, py::arg("height") = 0.06)
      .def_readonly("radius", &sm::Cone::radius, "base radius [m]")
      .def_readonly("height", &sm::Cone::height, "height [m]");
  shape_methods(cone);
  py::class_<sm::Ellipsoid> ellipsoid(m, "Ellipsoid",
                                      "Ellipsoid of `semi_axes` [m] along x, y, z.");
  ellipsoid
      .def(py::init([](const Eigen::Vector3d& e) { return sm::Ellipsoid(e); }),
           py::arg("semi_axes") = Eigen::Vector3d(0.05, 0.035, 0.025))
      .def_readonly("semi_axes", &sm::Ellipsoid::semi_axes, "semi-axes along x, y, z [m]");
  shape_methods(ellipsoid);
  py::class_<sm::Torus> torus(m, "Torus", "Torus around z.");
  torus
      .def(py::init<double, double>(), py::arg("major_radius") = 0.04,
           py::arg("minor_radius") = 0.015)
      .def_readonly("major_radius", &sm::Torus::major_radius,
                    "distance from the axis to the tube's centre [m]")
      .def_readonly("minor_radius", &sm::Torus::minor_radius, "the tube's radius [m]");
  shape_methods(torus);
  py::class_<sm::TriangleMesh> mesh(m, "TriangleMesh",
                                    "A closed triangle mesh; closest points through a bounding-"
                                    "volume hierarchy.");
  mesh.def(
      py::init([](const ArrayD& vertices, const ArrayI64& triangles) {
        std::vector<Vec3d> v = points_from(vertices, "vertices");
        require_shape(triangles, {-1, 3}, "triangles", "(T, 3)");
        std::vector<sm::TriangleMesh::Triangle> t(static_cast<std::size_t>(triangles.shape(0)));
        for (py::ssize_t i = 0; i < triangles.size(); ++i) {
          const std::int64_t k = triangles.data()[i];
          if (k < 0 || k > std::numeric_limits<std::uint32_t>::max()) {
            throw py::value_error("triangles: negative or too large vertex index " +
                                  std::to_string(k));
          }
          t[static_cast<std::size_t>(i / 3)][static_cast<std::size_t>(i % 3)] =
              static_cast<std::uint32_t>(k);
        }
        return sm::TriangleMesh(std::move(v), std::move(t));
      }),
      py::arg("vertices"), py::arg("triangles"));
  pickle_with(
      mesh, "TriangleMesh",
      [](const sm::TriangleMesh& t) {
        py::array_t<std::int64_t> tri(
            {static_cast<py::ssize_t>(t.triangles().size()), py::ssize_t{3}});
        for (std::size_t i = 0; i < t.triangles().size(); ++i) {
          for (std::size_t j = 0; j < 3; ++j) tri.mutable_data()[3 * i + j] = t.triangles()[i][j];
        }
        return py::make_tuple(points_array(t.vertices()), tri);
      },
      [](const py::tuple& a) {
        const auto v = a[0].cast<ArrayD>();
        const auto t = a[1].cast<ArrayI64>();
        require_shape(t, {-1, 3}, "pickled triangles", "(T, 3)");
        std::vector<sm::TriangleMesh::Triangle> tri(static_cast<std::size_t>(t.shape(0)));
        for (py::ssize_t i = 0; i < t.size(); ++i) {
          const std::int64_t k = t.data()[i];
          if (k < 0 || k >= v.shape(0)) throw py::value_error("pickled triangles: bad index");
          tri[static_cast<std::size_t>(i / 3)][static_cast<std::size_t>(i % 3)] =
              static_cast<std::uint32_t>(k);
        }
        return sm::TriangleMesh(points_from(v, "pickled vertices"), std::move(tri));
      });
  shape_methods(mesh);
  m.def("icosphere", &sm::icosphere<>, py::arg("radius"), py::arg("subdivisions"),
        "A sphere mesh: an icosahedron subdivided `subdivisions` times, vertices on the sphere.");
  m.def("box_mesh", &sm::box_mesh<>, py::arg("box"), "The box as a mesh of 12 triangles.");
  m.def("cylinder_mesh", &sm::cylinder_mesh<>, py::arg("cylinder"), py::arg("segments"),
        "The capped cylinder as a mesh with `segments` sides.");

  m.def(
      "surface_error",
      [](const py::object& shape, const ArrayD& points, const std::optional<ArrayD>& object_pose) {
        const AnyShape s = shape_from(shape);
        const std::vector<Vec3d> pts = points_from(points, "points");
        const Isometry3d pose =
            object_pose ? pose_from(*object_pose, "object_pose") : Isometry3d::Identity();
        const sm::SurfaceError e = std::visit(
            [&](const auto& sh) {
              using Sh = std::decay_t<decltype(sh)>;
              return sm::surface_error(sm::Posed<Sh>{sh, pose}, pts);
            },
            s);
        py::dict d;
        d["signed_mean"] = e.signed_mean;
        d["mean"] = e.mean;
        d["rms"] = e.rms;
        d["max"] = e.max;
        return d;
      },
      py::arg("shape"), py::arg("points"), py::arg("object_pose") = py::none(),
      "Distances [m] of (N, 3) points to the surface of `shape` placed at object_pose: "
      "'signed_mean' (outside positive), 'mean' |d|, 'rms', 'max' |d|.");

  py::class_<PyExploration> cls_exploration(m, "Exploration",
                                            "Frames of pad readings, poses and contacts.");
  pickle_with(
      cls_exploration, "Exploration",
      [](const PyExploration& e) {
        py::list frames;
        for (const auto& f : e.frames) {
          py::list pads;
          for (const auto& p : f.pads) {
            pads.append(py::make_tuple(p.pad, p.counts, detail::pickled(p.true_pose),
                                       detail::pickled(p.believed_pose)));
          }
          frames.append(py::make_tuple(f.time, pads, ContactList(f.contacts)));
        }
        return py::make_tuple(detail::pickled(e.object_pose), frames);
      },
      [](const py::tuple& a) {
        if (a.size() != 2) throw py::value_error("Exploration: damaged pickled state");
        PyExploration e;
        detail::unpickled(e.object_pose, a[0]);
        for (const auto& f : a[1].cast<py::list>()) {
          const auto t = f.cast<py::tuple>();
          sm::ExplorationFrame frame;
          frame.time = t[0].cast<double>();
          for (const auto& p : t[1].cast<py::list>()) {
            const auto q = p.cast<py::tuple>();
            sm::PadReading r;
            r.pad = q[0].cast<int>();
            r.counts = q[1].cast<decltype(r.counts)>();
            detail::unpickled(r.true_pose, q[2]);
            detail::unpickled(r.believed_pose, q[3]);
            frame.pads.push_back(std::move(r));
          }
          frame.contacts = t[2].cast<ContactList>();
          e.frames.push_back(std::move(frame));
        }
        return e;
      });
  cls_exploration.def("__len__", [](const PyExploration& e) { return e.frames.size(); })
      .def_property_readonly("object_pose",
                             [](const PyExploration& e) { return pose_array(e.object_pose); })
      .def_property_readonly(
          "times",
          [](const PyExploration& e) {
            py::array_t<double> out(static_cast<py::ssize_t>(e.frames.size()));
            for (std::size_t i = 0; i < e.frames.size(); ++i)
              out.mutable_data()[i] = e.frames[i].time;
            return out;
          },
          "(F,) frame times [s]")
      .def_property_readonly(
          "contacts",
          [](const PyExploration& e) {
            ContactList out;
            for (const auto& f : e.frames)
              out.insert(out.end(), f.contacts.begin(), f.contacts.end());
            return out;
          },
          "all contacts in time order (taxel.Contacts)")
      .def_property_readonly(
          "readings",
          [](const PyExploration& e) {
            const std::size_t pads = pads_per_frame(e);
            const auto r = e.frames.empty() || pads == 0 ? 0 : e.frames[0].pads[0].counts.rows();
            const auto c = e.frames.empty() || pads == 0 ? 0 : e.frames[0].pads[0].counts.cols();
            py::array_t<std::uint16_t> out(
                {static_cast<py::ssize_t>(e.frames.size()), static_cast<py::ssize_t>(pads),
                 static_cast<py::ssize_t>(r), static_cast<py::ssize_t>(c)});
            std::uint16_t* o = out.mutable_data();
            for (const auto& f : e.frames) {
              for (const auto& p : f.pads)
                o = std::copy(p.counts.data(), p.counts.data() + p.counts.size(), o);
            }
            return out;
          },
          "(F, P, rows, cols) uint16 readings of every pad in every frame")
      .def(
          "poses",
          [](const PyExploration& e, bool believed) {
            const std::size_t pads = pads_per_frame(e);
            ArrayD out({static_cast<py::ssize_t>(e.frames.size()), static_cast<py::ssize_t>(pads),
                        py::ssize_t{4}, py::ssize_t{4}});
            double* o = out.mutable_data();
            for (const auto& f : e.frames) {
              for (const auto& p : f.pads) {
                const Eigen::Matrix4d t = (believed ? p.believed_pose : p.true_pose).matrix();
                for (int r = 0; r < 4; ++r) {
                  for (int c = 0; c < 4; ++c) *o++ = t(r, c);
                }
              }
            }
            return out;
          },
          py::kw_only(), py::arg("believed") = true,
          "(F, P, 4, 4) pad -> world poses: as the robot believes them (with kinematic noise; "
          "the contacts use these) or, with believed=False, the true ones");

  m.def(
      "explore_sliding",
      [](const py::object& shape, int slides, std::size_t frames, double speed,
         double heading_sigma, const sensor::SensorModel& sensor,
         const sensor::ContactOptions& contacts, double frame_rate, double indentation,
         const std::optional<ArrayD>& object_pose, std::uint64_t seed) {
        const auto cfg =
            exploration_config(sensor, contacts, frame_rate, indentation, object_pose, seed);
        const sm::SlideParams p{slides, frames, speed, heading_sigma};
        return explore(shape, cfg, [&](const auto& sh, const auto& c) {
          return sm::explore_sliding(sh, c, p);
        });
      },
      py::arg("shape"), py::kw_only(), py::arg("slides") = 4, py::arg("frames") = 1000,
      py::arg("speed") = 0.05, py::arg("heading_sigma") = 0.05, TAXEL_EXPLORATION_ARGS,
      "Slides one pad over the shape: `slides` slides of `frames` frames from random starts.");
  m.def(
      "explore_grasps",
      [](const py::object& shape, int grasps, int fingers, int pads_per_finger, double pad_spacing,
         double closing_speed, int hold_frames, const sensor::SensorModel& sensor,
         const sensor::ContactOptions& contacts, double frame_rate, double indentation,
         const std::optional<ArrayD>& object_pose, std::uint64_t seed) {
        const auto cfg =
            exploration_config(sensor, contacts, frame_rate, indentation, object_pose, seed);
        const sm::GraspParams p{grasps,      fingers,       pads_per_finger,
                                pad_spacing, closing_speed, hold_frames};
        return explore(shape, cfg,
                       [&](const auto& sh, const auto& c) { return sm::explore_grasps(sh, c, p); });
      },
      py::arg("shape"), py::kw_only(), py::arg("grasps") = 8, py::arg("fingers") = 3,
      py::arg("pads_per_finger") = 2, py::arg("pad_spacing") = 0.05,
      py::arg("closing_speed") = 0.05, py::arg("hold_frames") = 50, TAXEL_EXPLORATION_ARGS,
      "Closes a hand of fingers x pads_per_finger pads on the shape `grasps` times.");
  m.def(
      "explore_palpation",
      [](const py::object& shape, int touches, double press_speed, int hold_frames,
         const sensor::SensorModel& sensor, const sensor::ContactOptions& contacts,
         double frame_rate, double indentation, const std::optional<ArrayD>& object_pose,
         std::uint64_t seed) {
        const auto cfg =
            exploration_config(sensor, contacts, frame_rate, indentation, object_pose, seed);
        const sm::PalpationParams p{touches, press_speed, hold_frames};
        return explore(shape, cfg, [&](const auto& sh, const auto& c) {
          return sm::explore_palpation(sh, c, p);
        });
      },
      py::arg("shape"), py::kw_only(), py::arg("touches") = 40, py::arg("press_speed") = 0.02,
      py::arg("hold_frames") = 10, TAXEL_EXPLORATION_ARGS,
      "Presses one pad onto the shape `touches` times.");

  py::class_<sm::PalmGraspSynth> cls_palmgraspsynth(m, "PalmGraspSynth", R"doc(
Synthetic palm pressure images (rows x cols, 0..255) of four grasp classes: 1 planar,
2 one-edged, 3 two-edged, 4 cylindrical; subjects differ in hand size, finger width and force.)doc");
  pickle_with(
      cls_palmgraspsynth, "PalmGraspSynth",
      [](const sm::PalmGraspSynth& g) {
        return py::make_tuple(g.config().rows, g.config().cols, g.config().fingers, g.seed());
      },
      [](const py::tuple& a) {
        sm::PalmGraspConfig c;
        c.rows = a[0].cast<int>();
        c.cols = a[1].cast<int>();
        c.fingers = a[2].cast<int>();
        return sm::PalmGraspSynth(c, a[3].cast<std::uint64_t>());
      });
  cls_palmgraspsynth
      .def(py::init([](int rows, int cols, int fingers, std::uint64_t seed) {
             sm::PalmGraspConfig c;
             c.rows = rows;
             c.cols = cols;
             c.fingers = fingers;
             return sm::PalmGraspSynth(c, seed);
           }),
           py::arg("rows") = 32, py::arg("cols") = 32, py::kw_only(), py::arg("fingers") = 4,
           py::arg("seed") = 1)
      .def(
          "dataset",
          [](const sm::PalmGraspSynth& s, int subjects, int grasps) {
            std::vector<sm::PalmGraspSample> d;
            {
              py::gil_scoped_release release;
              d = s.dataset(subjects, grasps);
            }
            const auto n = static_cast<py::ssize_t>(d.size());
            const py::ssize_t r = s.config().rows, c = s.config().cols;
            ArrayD images({n, r, c});
            py::array_t<int> labels(n), subject(n);
            py::array_t<bool> right(n);
            for (py::ssize_t i = 0; i < n; ++i) {
              const auto& x = d[static_cast<std::size_t>(i)];
              std::copy(x.image.data(), x.image.data() + x.image.size(),
                        images.mutable_data() + i * r * c);
              labels.mutable_data()[i] = static_cast<int>(x.label);
              subject.mutable_data()[i] = x.subject;
              right.mutable_data()[i] = x.right_hand;
            }
            py::dict out;
            out["images"] = images;
            out["labels"] = labels;
            out["subjects"] = subject;
            out["right_hand"] = right;
            return out;
          },
          py::arg("subjects"), py::arg("grasps"),
          "subjects x 4 classes x grasps x 2 hands images: a dict of 'images' (N, rows, cols), "
          "'labels' (N,) 1..4, 'subjects' (N,) and 'right_hand' (N,).");
}

}  // namespace taxel::python
