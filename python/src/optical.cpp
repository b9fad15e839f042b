// SPDX-License-Identifier: MIT
// taxel.optical: camera-based tactile sensors (GelSight and DIGIT class): calibration from
// ball presses, frames to heights and contact masks, marker dots tracked as a displacement
// field. Frames are numpy uint8 arrays of shape (rows, cols, 3), RGB.
#include <optional>

#include "common.hpp"
#include "taxel/optical.hpp"

namespace taxel::python {
namespace {

namespace to = taxel::optical;

to::RgbFrame frame_from(const ArrayU8& a, const char* what) {
  if (a.ndim() != 3 || a.shape(2) != 3) {
    throw py::value_error(std::string(what) +
                          ": expected an RGB frame of shape (rows, cols, 3), got " + shape_text(a));
  }
  to::RgbFrame f(a.shape(0), a.shape(1), 0);
  std::memcpy(f.data.data(), a.data(), f.data.size());
  to::validate_frame(f, what);
  return f;
}

py::array_t<std::uint8_t> frame_array(const to::RgbFrame& f) {
  py::array_t<std::uint8_t> out({f.rows, f.cols, Eigen::Index{3}});
  std::memcpy(out.mutable_data(), f.data.data(), f.data.size());
  return out;
}

/// Frames from a list of (rows, cols, 3) arrays or one (frames, rows, cols, 3) array.
std::vector<to::RgbFrame> frames_from(const py::handle& src, const char* what) {
  std::vector<to::RgbFrame> out;
  if (py::isinstance<py::array>(src) && py::reinterpret_borrow<py::array>(src).ndim() == 4) {
    const ArrayU8 a = src.cast<ArrayU8>();
    if (a.shape(3) != 3) {
      throw py::value_error(std::string(what) +
                            ": expected frames of shape (frames, rows, cols, 3), got " +
                            shape_text(a));
    }
    const auto per = static_cast<std::size_t>(a.shape(1) * a.shape(2) * 3);
    for (py::ssize_t i = 0; i < a.shape(0); ++i) {
      to::RgbFrame f(a.shape(1), a.shape(2), 0);
      std::memcpy(f.data.data(), a.data() + static_cast<std::size_t>(i) * per, per);
      to::validate_frame(f, what);
      out.push_back(std::move(f));
    }
    return out;
  }
  for (const py::handle item : src) out.push_back(frame_from(item.cast<ArrayU8>(), what));
  return out;
}

template <class Plane>
ArrayD plane_array(const Plane& p) {
  ArrayD out({p.rows(), p.cols()});
  Eigen::Map<Eigen::Array<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      out.mutable_data(), p.rows(), p.cols()) = p.template cast<double>();
  return out;
}

/// Dots from find_dots' (dots, 3) array: column, row, area.
std::vector<to::Dot> dots_from(const ArrayD& dots) {
  require_shape(dots, {-1, 3}, "dots", "(dots, 3)");
  std::vector<to::Dot> v;
  for (py::ssize_t i = 0; i < dots.shape(0); ++i) {
    v.push_back({dots.at(i, 0), dots.at(i, 1), dots.at(i, 2)});
  }
  return v;
}

const char* method_name(to::Calibration::Method m) {
  return m == to::Calibration::Method::polynomial ? "polynomial" : "lookup_table";
}

/// A reconstructor: its own copy of a calibration (whose background may follow a drift), and
/// the Poisson solver for its frame size.
struct Reconstructor {
  to::Calibration calibration;
  to::PoissonSolver solver;
  double drift_rate = 0;
  Reconstructor(const to::Calibration& c, double rate)
      : calibration(c), solver(c.rows, c.cols), drift_rate(rate) {
    if (!(rate >= 0 && rate <= 1)) throw py::value_error("drift_rate must be in [0, 1]");
  }
};

/// The map's arrays handed to numpy without a copy: each a view of the map's own planes, which
/// a capsule keeps alive until the last array is gone. The masks hold 0 and 1, numpy's bools.
py::dict height_map_dict(to::HeightMap&& m) {
  for (image::Mask* mask : {&m.mask, &m.contact}) *mask = (*mask != 0).cast<std::uint8_t>();
  auto* held = new to::HeightMap(std::move(m));
  const py::capsule owner(held, [](void* p) { delete static_cast<to::HeightMap*>(p); });
  const auto plane = [&](const to::Plane& p) {
    return py::array_t<double>({p.rows(), p.cols()}, p.data(), owner);
  };
  const auto mask = [&](const image::Mask& k) {
    return py::array_t<bool>({k.rows(), k.cols()}, reinterpret_cast<const bool*>(k.data()), owner);
  };
  py::dict d;
  d["height"] = plane(held->height);
  d["gx"] = plane(held->gx);
  d["gy"] = plane(held->gy);
  d["mask"] = mask(held->mask);
  d["contact"] = mask(held->contact);
  return d;
}

to::HeightMap run(Reconstructor& r, const ArrayU8& frame, const to::ReconstructOptions& o) {
  const to::RgbFrame f = frame_from(frame, "reconstruct");
  py::gil_scoped_release release;
  const auto lock = write_lock(&r);  // the solver's workspace and the background
  to::HeightMap map = to::reconstruct(f, r.calibration, r.solver, o);
  if (r.drift_rate > 0) to::track_background(r.calibration, f, map, r.drift_rate);
  return map;
}

}  // namespace

void bind_optical(py::module_& m) {
  auto o = m.def_submodule("optical", R"doc(Camera-based tactile sensors (GelSight, DIGIT).

Frames are numpy uint8 arrays of shape (rows, cols, 3), RGB. ``calibrate`` builds the map from
colour change to surface slope from ball presses; ``Reconstructor`` (or ``reconstruct``) turns
a frame into heights in metres, positive into the gel, and masks; ``find_dots`` and
``MarkerTracker`` follow the gel's marker dots as a displacement field in pixels.)doc");

  using CalPtr = std::shared_ptr<to::Calibration>;
  py::class_<to::Calibration, CalPtr> calibration_cls(o, "Calibration", R"doc(
A map from colour change to surface slope, with the background frame it was made over, each
press's contact circle and the held-out slope errors. Immutable; ``save`` and ``load`` keep it
in a file (JSON when the name ends in .json, binary .txcal otherwise).)doc");
  calibration_cls.def(py::pickle(
      [](const to::Calibration& c) {
        return py::make_tuple(1, py::bytes(to::encode_calibration(c)));
      },
      [](const py::tuple& t) {
        if (t.size() != 2 || t[0].cast<int>() != 1) {
          throw py::value_error("Calibration: not a pickled state of version 1");
        }
        return std::make_shared<to::Calibration>(to::decode_calibration(
            std::string_view(t[1].cast<py::bytes>()), "pickled Calibration"));
      }));
  // Immutable: a copy may share it.
  calibration_cls.def("__copy__", [](const py::object& self) { return self; });
  calibration_cls.def(
      "__deepcopy__", [](const py::object& self, const py::dict&) { return self; },
      py::arg("memo"));
  calibration_cls
      .def_property_readonly(
          "rows", [](const to::Calibration& c) { return c.rows; },
          "Frame rows the calibration is for.")
      .def_property_readonly(
          "cols", [](const to::Calibration& c) { return c.cols; },
          "Frame columns the calibration is for.")
      .def_property_readonly(
          "pixel", [](const to::Calibration& c) { return c.pixel; },
          "The gel's size of one pixel [m].")
      .def_property_readonly(
          "method", [](const to::Calibration& c) { return method_name(c.method); },
          "The map kept: 'polynomial' or 'lookup_table' (the lower held-out error).")
      .def_property_readonly(
          "heldout", [](const to::Calibration& c) { return c.heldout(); },
          "Held-out RMS slope error of the map kept.")
      .def_property_readonly(
          "heldout_polynomial", [](const to::Calibration& c) { return c.heldout_polynomial; },
          "Held-out RMS slope error of the polynomial.")
      .def_property_readonly(
          "heldout_table", [](const to::Calibration& c) { return c.heldout_table; },
          "Held-out RMS slope error of the lookup table.")
      .def_property_readonly(
          "circles",
          [](const to::Calibration& c) {
            ArrayD out({static_cast<py::ssize_t>(c.circles.size()), py::ssize_t{3}});
            double* p = out.mutable_data();
            for (const to::Circle& k : c.circles) {
              *p++ = k.cx;
              *p++ = k.cy;
              *p++ = k.radius;
            }
            return out;
          },
          "Each press's contact circle, (presses, 3): centre column, centre row, radius [px].")
      .def(
          "save",
          [](const to::Calibration& c, const std::string& path) {
            py::gil_scoped_release release;
            to::save_calibration(path, c);
          },
          py::arg("path"),
          "Writes the calibration (JSON when `path` ends in .json, else binary), whole or not "
          "at all. Raises taxel.IoError.")
      .def_static(
          "load",
          [](const std::string& path) {
            py::gil_scoped_release release;
            return std::make_shared<to::Calibration>(to::load_calibration(path));
          },
          py::arg("path"), "Reads a calibration file of either form. Raises taxel.IoError.")
      .def("__repr__", [](const to::Calibration& c) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      "<Calibration %dx%d px of %.4g mm, %zu presses, %s, held-out %.3f>", c.rows,
                      c.cols, c.pixel * 1e3, c.circles.size(), method_name(c.method), c.heldout());
        return std::string(buf);
      });

  o.def(
      "calibrate",
      [](const py::object& presses, const ArrayU8& background, double ball_radius, double pixel,
         const std::optional<ArrayD>& circles, double threshold, int table_bins, bool markers) {
        const std::vector<to::RgbFrame> frames = frames_from(presses, "calibrate (presses)");
        const to::RgbFrame bg = frame_from(background, "calibrate (background)");
        std::vector<to::Circle> given;
        if (circles) {
          require_shape(*circles, {-1, 3}, "circles", "(presses, 3)");
          for (py::ssize_t i = 0; i < circles->shape(0); ++i) {
            given.push_back({circles->at(i, 0), circles->at(i, 1), circles->at(i, 2)});
          }
        }
        to::CalibrationOptions opt;
        opt.ball_radius = ball_radius;
        opt.pixel = pixel;
        opt.threshold = threshold;
        opt.table_bins = table_bins;
        opt.markers = markers;
        py::gil_scoped_release release;
        return std::make_shared<to::Calibration>(to::calibrate(frames, bg, opt, given));
      },
      py::arg("presses"), py::arg("background"), py::kw_only(), py::arg("ball_radius"),
      py::arg("pixel"), py::arg("circles") = py::none(), py::arg("threshold") = 12.0,
      py::arg("table_bins") = 32, py::arg("markers") = true, R"doc(
Calibrates from ball presses over a no-contact `background` frame.

`presses` is a list of (rows, cols, 3) uint8 frames or one (frames, rows, cols, 3) array;
`ball_radius` and `pixel` (the gel's size of one pixel) are in metres. Each press's contact
circle is found (``Calibration.circles``) unless `circles` gives them, (presses, 3) as centre
column, centre row and radius in pixels. Raises ValueError for bad options or sizes and
RuntimeError naming a press without contact.)doc");

  o.def(
      "median_background",
      [](const py::object& frames) {
        const std::vector<to::RgbFrame> f = frames_from(frames, "median_background");
        to::RgbFrame out;
        {
          py::gil_scoped_release release;
          out = to::median_background(f);
        }
        return frame_array(out);
      },
      py::arg("frames"),
      "The per-pixel median of frames that mostly show the untouched gel, as a background.");

  py::class_<Reconstructor> cls_reconstructor(o, "Reconstructor", R"doc(
Frames to height maps with one calibration: keeps the Poisson solver of the calibration's frame
size, so that a stream of frames does not plan it again. Calls on one reconstructor run one at
a time; use one per thread to run them together.)doc");
  pickle_with<false>(
      cls_reconstructor, "Reconstructor",
      [](const Reconstructor& r) {
        const auto lock = read_lock(&r);
        // The calibration, and its background as it has drifted, in full precision (the file
        // keeps it to 8 bits); the solver is a cache.
        const auto& bg = r.calibration.background;
        return py::make_tuple(py::bytes(to::encode_calibration(r.calibration)), r.drift_rate, bg[0],
                              bg[1], bg[2]);
      },
      [](const py::tuple& a) {
        if (a.size() != 5) throw py::value_error("Reconstructor: damaged pickled state");
        Reconstructor r(to::decode_calibration(std::string_view(a[0].cast<py::bytes>()),
                                               "pickled Reconstructor"),
                        a[1].cast<double>());
        for (std::size_t c = 0; c < 3; ++c) {
          auto plane = a[2 + c].cast<to::Plane>();
          if (plane.rows() != r.calibration.background[c].rows() ||
              plane.cols() != r.calibration.background[c].cols()) {
            throw py::value_error("Reconstructor: the pickled background's size is wrong");
          }
          r.calibration.background[c] = std::move(plane);
        }
        return r;
      });
  cls_reconstructor
      .def(py::init(
               [](const CalPtr& c, double drift_rate) { return Reconstructor(*c, drift_rate); }),
           py::arg("calibration"), py::kw_only(), py::arg("drift_rate") = 0.0,
           "A reconstructor for frames of the calibration's size. With `drift_rate` > 0 its "
           "background follows a slow drift of the lighting: after each frame it moves toward "
           "the frame by that share where the gel is untouched.")
      .def_property_readonly(
          "calibration",
          [](const Reconstructor& r) {
            const auto lock = read_lock(&r);
            return std::make_shared<to::Calibration>(r.calibration);
          },
          "A copy of the calibration in use (its background as followed so far).")
      .def_property_readonly(
          "drift_rate", [](const Reconstructor& r) { return r.drift_rate; },
          "The share by which the background follows each frame (0: it stays).")
      .def(
          "__call__",
          [](Reconstructor& r, const ArrayU8& frame, int grow, int min_area, double contact_share) {
            to::ReconstructOptions opt;
            opt.grow = grow;
            opt.min_area = min_area;
            opt.contact_share = contact_share;
            return height_map_dict(run(r, frame, opt));
          },
          py::arg("frame"), py::kw_only(), py::arg("grow") = 2, py::arg("min_area") = 30,
          py::arg("contact_share") = 0.3, R"doc(
The height map of a (rows, cols, 3) uint8 frame, as a dict of arrays: 'height' (metres,
positive into the gel, the untouched gel averaging 0), 'gx' and 'gy' (slopes), 'mask' (bool,
the deformed gel) and 'contact' (bool, the deformed pixels at least `contact_share` of the
deepest height). Raises ValueError for a frame of another size or one with no gel in view.)doc")
      .def("__repr__", [](const Reconstructor& r) {
        return "<Reconstructor " + std::to_string(r.calibration.rows) + "x" +
               std::to_string(r.calibration.cols) + (r.drift_rate > 0 ? ", following drift>" : ">");
      });

  o.def(
      "reconstruct",
      [](const ArrayU8& frame, const CalPtr& calibration, double contact_share) {
        Reconstructor r(*calibration, 0.0);
        to::ReconstructOptions opt;
        opt.contact_share = contact_share;
        return height_map_dict(run(r, frame, opt));
      },
      py::arg("frame"), py::arg("calibration"), py::kw_only(), py::arg("contact_share") = 0.3,
      "One frame's height map (see Reconstructor.__call__); plans a Poisson solver each call.");

  o.def(
      "fit_ball",
      [](const py::array_t<double>& height, const py::array_t<bool>& contact, double pixel) {
        if (height.ndim() != 2 || contact.ndim() != 2 || height.shape(0) != contact.shape(0) ||
            height.shape(1) != contact.shape(1)) {
          throw py::value_error("fit_ball: height and contact must be 2-D arrays of one shape");
        }
        to::HeightMap map;
        map.height.resize(height.shape(0), height.shape(1));
        map.contact.resize(height.shape(0), height.shape(1));
        const auto h = height.unchecked<2>();
        const auto c = contact.unchecked<2>();
        for (py::ssize_t r = 0; r < height.shape(0); ++r) {
          for (py::ssize_t k = 0; k < height.shape(1); ++k) {
            map.height(r, k) = h(r, k);
            map.contact(r, k) = c(r, k) ? 1 : 0;
          }
        }
        const to::BallFit f = to::fit_ball(map, pixel);
        return py::make_tuple(f.radius, f.cx, f.cy);
      },
      py::arg("height"), py::arg("contact"), py::arg("pixel"),
      "The sphere through the contact's surface points: (radius [m], centre column, centre row "
      "[px]). Raises RuntimeError when the contact has fewer than 10 pixels.");

  o.def(
      "find_dots",
      [](const ArrayU8& frame) {
        const to::RgbFrame f = frame_from(frame, "find_dots");
        std::vector<to::Dot> dots;
        {
          py::gil_scoped_release release;
          dots = to::find_dots(f);
        }
        ArrayD out({static_cast<py::ssize_t>(dots.size()), py::ssize_t{3}});
        double* p = out.mutable_data();
        for (const to::Dot& d : dots) {
          *p++ = d.x;
          *p++ = d.y;
          *p++ = d.area;
        }
        return out;
      },
      py::arg("frame"),
      "The marker dots of a frame, (dots, 3): centre column, centre row [px] and area [px].");

  py::class_<to::MarkerTracker> cls_markertracker(o, "MarkerTracker", R"doc(
Follows marker dots from a frame of the gel at rest through later frames, as a displacement
field: lost dots are placed by their neighbours' motion, new dots start new tracks.)doc");
  pickle_with(
      cls_markertracker, "MarkerTracker",
      [](const to::MarkerTracker& t) {
        const auto lock = read_lock(&t);
        ArrayD rows({static_cast<py::ssize_t>(t.tracks().size()), py::ssize_t{6}});
        double* p = rows.mutable_data();
        for (const auto& k : t.tracks()) {
          *p++ = k.x0;
          *p++ = k.y0;
          *p++ = k.x;
          *p++ = k.y;
          *p++ = k.seen ? 1.0 : 0.0;
          *p++ = k.missed;
        }
        return py::make_tuple(t.options().max_step, t.options().neighbours, rows);
      },
      [](const py::tuple& a) {
        if (a.size() != 3) throw py::value_error("MarkerTracker: damaged pickled state");
        const auto rows = a[2].cast<ArrayD>();
        require_shape(rows, {-1, 6}, "pickled tracks", "(N, 6)");
        std::vector<to::MarkerTrack> tracks(static_cast<std::size_t>(rows.shape(0)));
        const double* p = rows.data();
        for (auto& k : tracks) {
          k = {p[0], p[1], p[2], p[3], p[4] != 0.0, static_cast<int>(p[5])};
          p += 6;
        }
        to::TrackerOptions options;
        options.max_step = a[0].cast<double>();
        options.neighbours = a[1].cast<int>();
        try {
          return to::MarkerTracker::restore(std::move(tracks), options);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      });
  cls_markertracker
      .def(py::init([](const ArrayD& dots, double max_step) {
             return to::MarkerTracker(dots_from(dots), {.max_step = max_step});
           }),
           py::arg("dots"), py::kw_only(), py::arg("max_step") = 0.0,
           "Tracks for the dots of the reference frame (find_dots' array); `max_step` 0: 0.4 "
           "times their median spacing.")
      .def(
          "update",
          [](to::MarkerTracker& t, const ArrayD& dots) {
            const std::vector<to::Dot> v = dots_from(dots);
            py::gil_scoped_release release;
            const auto lock = write_lock(&t);
            return t.update(v);
          },
          py::arg("dots"), "Follows the dots of the next frame; returns the tracks found.")
      .def_property_readonly(
          "tracks",
          [](const to::MarkerTracker& t) {
            const auto lock = read_lock(&t);
            ArrayD out({static_cast<py::ssize_t>(t.tracks().size()), py::ssize_t{6}});
            double* p = out.mutable_data();
            for (const to::MarkerTrack& k : t.tracks()) {
              *p++ = k.x0;
              *p++ = k.y0;
              *p++ = k.x;
              *p++ = k.y;
              *p++ = k.seen ? 1.0 : 0.0;
              *p++ = k.missed;
            }
            return out;
          },
          "Every track, (tracks, 6): rest column, rest row, column, row [px], seen in the last "
          "frame (1 or 0), frames missed in a row.")
      .def_property_readonly("max_step", &to::MarkerTracker::max_step,
                             "The pairing distance in use [px].")
      .def(
          "field",
          [](const to::MarkerTracker& t, int rows, int cols) {
            to::Plane dx, dy;
            {
              py::gil_scoped_release release;
              const auto lock = read_lock(&t);
              t.field(rows, cols, dx, dy);
            }
            return py::make_tuple(plane_array(dx), plane_array(dy));
          },
          py::arg("rows"), py::arg("cols"),
          "The displacement field of the last frame at every pixel, (dx, dy) [px].")
      .def("__repr__", [](const to::MarkerTracker& t) {
        const auto lock = read_lock(&t);
        std::size_t seen = 0;
        for (const auto& k : t.tracks()) seen += k.seen;
        return "<MarkerTracker " + std::to_string(t.tracks().size()) + " tracks, " +
               std::to_string(seen) + " seen>";
      });
}

}  // namespace taxel::python
