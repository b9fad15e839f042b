// SPDX-License-Identifier: MIT
// taxel.PointCloud and taxel.Contacts: the containers the other modules pass around.
#include <cmath>
#include <string>

#include "common.hpp"

namespace taxel::python {

Cloud cloud_from(const ArrayD& points, const std::optional<ArrayD>& normals, const char* what) {
  Cloud c;
  c.points = points_from(points, what);
  if (normals) {
    c.normals = points_from(*normals, "normals");
    if (c.normals.size() != c.points.size()) {
      throw py::value_error(std::string(what) + ": " + std::to_string(c.normals.size()) +
                            " normals for " + std::to_string(c.points.size()) + " points");
    }
  }
  return c;
}

ContactRows contact_rows(ArrayD positions, std::optional<ArrayD> covariances,
                         std::optional<ArrayD> normals, std::optional<ArrayD> pressures,
                         std::optional<ArrayD> times, std::optional<double> sigma,
                         double footprint_sigma) {
  require_shape(positions, {-1, 3}, "positions", "(N, 3)");
  if (!(footprint_sigma >= 0) || !std::isfinite(footprint_sigma)) {
    throw py::value_error("footprint_sigma must be finite and >= 0 [m], got " +
                          std::to_string(footprint_sigma));
  }
  ContactRows r;
  r.n = static_cast<std::size_t>(positions.shape(0));
  const auto n = static_cast<py::ssize_t>(r.n);
  if (covariances && sigma) {
    throw py::value_error("give covariances or sigma, not both");
  }
  if (sigma) {
    r.default_covariance = isotropic_covariance(*sigma);  // throws for sigma <= 0
  }
  if (covariances) {
    if (covariances->ndim() == 2) {
      require_shape(*covariances, {3, 3}, "covariances", "(N, 3, 3) or (3, 3)");
    } else {
      require_shape(*covariances, {n, 3, 3}, "covariances", "(N, 3, 3) or (3, 3)");
    }
  }
  if (normals) require_shape(*normals, {n, 3}, "normals", "(N, 3) like positions");
  if (pressures) require_shape(*pressures, {n}, "pressures", "(N,) like positions");
  if (times) require_shape(*times, {n}, "times", "(N,) like positions");
  r.positions = std::move(positions);
  r.covariances = std::move(covariances);
  r.normals = std::move(normals);
  r.pressures = std::move(pressures);
  r.times = std::move(times);
  r.footprint_sigma = footprint_sigma;
  return r;
}

namespace {

constexpr py::ssize_t kContactRow = 20;  // doubles per contact in a pickled Contacts

ArrayD covariances_array(const ContactList& cs) {
  ArrayD out({static_cast<py::ssize_t>(cs.size()), py::ssize_t{3}, py::ssize_t{3}});
  double* p = out.mutable_data();
  for (const auto& c : cs) {
    store(p, c.covariance);
    p += 9;
  }
  return out;
}

// One scalar field of every contact as an (N,) array.
template <double Contact<double>::*Field>
py::array_t<double> contact_column(const ContactList& cs) {
  py::array_t<double> out(static_cast<py::ssize_t>(cs.size()));
  double* p = out.mutable_data();
  for (const auto& c : cs) *p++ = c.*Field;
  return out;
}

}  // namespace

void bind_core(py::module_& m) {
  py::class_<Cloud>(m, "PointCloud", R"doc(
Points [m] with optional unit normals and named per-point scalar fields.

Arrays are copied in. Out, ``cloud.points`` (N, 3), ``cloud.normals`` (N, 3) or None and the
(N,) arrays of ``cloud.fields`` are read-only views of the cloud's memory (no copy; each keeps
the cloud alive). A PointCloud never changes once made, so the views stay valid; copy one
(``np.array(cloud.points)``) to change it. Clouds pickle and deep-copy.)doc")
      .def(py::init([](ArrayD points, std::optional<ArrayD> normals,
                       std::optional<std::map<std::string, ArrayD>> fields) {
             Cloud c = cloud_from(points, normals, "points");
             if (fields) {
               for (const auto& [name, values] : *fields) {
                 require_shape(values, {static_cast<py::ssize_t>(c.size())}, name.c_str(),
                               "(N,) like points");
                 c.fields.push_back(
                     {name, std::vector<double>(values.data(), values.data() + values.size())});
               }
             }
             return c;
           }),
           py::arg("points"), py::arg("normals") = py::none(), py::arg("fields") = py::none())
      .def("__len__", &Cloud::size)
      .def_property_readonly(
          "points",
          [](const py::object& self) -> ArrayD {
            return readonly_points(self.cast<const Cloud&>().points, self);
          },
          "(N, 3) positions [m], a read-only view")
      .def_property_readonly(
          "normals",
          [](const py::object& self) -> std::optional<ArrayD> {
            const Cloud& c = self.cast<const Cloud&>();
            if (!c.has_normals()) return std::nullopt;
            return ArrayD(readonly_points(c.normals, self));
          },
          "(N, 3) unit normals, a read-only view, or None")
      .def_property_readonly(
          "fields",
          [](const py::object& self) {
            std::map<std::string, ArrayD> out;
            for (const auto& f : self.cast<const Cloud&>().fields) {
              out[f.name] = readonly_vector(f.values, self);
            }
            return out;
          },
          "per-point scalars by name, each a read-only (N,) view")
      .def(py::pickle(
          [](const py::object& self) {
            const Cloud& c = self.cast<const Cloud&>();
            py::dict fields;
            for (const auto& f : c.fields) fields[py::str(f.name)] = vector_array(f.values);
            return py::make_tuple(
                1, points_array(c.points),
                c.has_normals() ? py::object(points_array(c.normals)) : py::none(), fields);
          },
          [](const py::tuple& t) {
            if (t.size() != 4 || t[0].cast<int>() != 1) {
              throw py::value_error("PointCloud: not a pickled state of version 1");
            }
            Cloud c = cloud_from(t[1].cast<ArrayD>(),
                                 t[2].is_none() ? std::optional<ArrayD>{} : t[2].cast<ArrayD>(),
                                 "points");
            for (const auto& [name, values] : t[3].cast<py::dict>()) {
              const auto v = values.cast<ArrayD>();
              require_shape(v, {static_cast<py::ssize_t>(c.size())}, "a pickled field",
                            "(N,) like points");
              c.fields.push_back(
                  {name.cast<std::string>(), std::vector<double>(v.data(), v.data() + v.size())});
            }
            return c;
          }))
      .def("__copy__", [](const py::object& self) { return self; })
      .def(
          "__deepcopy__", [](const py::object& self, const py::dict&) { return self; },
          py::arg("memo"))
      .def("__repr__", [](const Cloud& c) {
        return "PointCloud(" + std::to_string(c.size()) + " points" +
               (c.has_normals() ? ", normals" : "") +
               (c.fields.empty() ? "" : ", " + std::to_string(c.fields.size()) + " fields") + ")";
      });

  py::class_<ContactList>(m, "Contacts", R"doc(
Tactile contacts held in C++: positions [m] (world frame), covariances [m^2], optional unit
normals (a NaN row when absent), pressures and times [s].

Made from arrays, or returned by the readers, the simulator and
``taxel.sensor.contacts_from_readings``. Inserting a ``Contacts`` into a ``ContactCloud`` runs
the C++ loop with no conversion.)doc")
      .def(py::init([](ArrayD positions, std::optional<ArrayD> covariances,
                       std::optional<ArrayD> normals, std::optional<ArrayD> pressures,
                       std::optional<ArrayD> times, std::optional<double> sigma,
                       double footprint_sigma) {
             const ContactRows rows =
                 contact_rows(std::move(positions), std::move(covariances), std::move(normals),
                              std::move(pressures), std::move(times), sigma, footprint_sigma);
             ContactList out(rows.n);
             for (std::size_t i = 0; i < rows.n; ++i) out[i] = rows.at(i);
             return out;
           }),
           py::arg("positions"), py::arg("covariances") = py::none(),
           py::arg("normals") = py::none(), py::arg("pressures") = py::none(),
           py::arg("times") = py::none(), py::arg("sigma") = py::none(),
           py::arg("footprint_sigma") = 0.0,
           "Contacts from (N, 3) positions; covariances (N, 3, 3) or one (3, 3) for all, or an "
           "isotropic `sigma` [m]; the default is 1 mm isotropic. `footprint_sigma` [m]: how "
           "much of the covariance across the normal is a footprint around a point on the "
           "surface rather than scatter of the position (0: all scatter; a tactel of pitch p "
           "read at its centre: p / sqrt(12)).")
      .def("__len__", &ContactList::size)
      .def_property_readonly(
          "positions",
          [](const ContactList& cs) {
            ArrayD out({static_cast<py::ssize_t>(cs.size()), py::ssize_t{3}});
            double* p = out.mutable_data();
            for (const auto& c : cs) {
              store(p, c.position);
              p += 3;
            }
            return out;
          },
          "(N, 3) positions [m]")
      .def_property_readonly("covariances", &covariances_array, "(N, 3, 3) covariances [m^2]")
      .def_property_readonly(
          "normals",
          [](const ContactList& cs) {
            ArrayD out({static_cast<py::ssize_t>(cs.size()), py::ssize_t{3}});
            double* p = out.mutable_data();
            for (const auto& c : cs) {
              store(p, c.normal ? *c.normal
                                : Vec3d::Constant(std::numeric_limits<double>::quiet_NaN()));
              p += 3;
            }
            return out;
          },
          "(N, 3) unit normals; NaN rows where a contact has none")
      .def_property_readonly("pressures", &contact_column<&Contact<double>::pressure>,
                             "(N,) pressures")
      .def_property_readonly("times", &contact_column<&Contact<double>::time>, "(N,) times [s]")
      .def_property_readonly(
          "normal_sigmas", &contact_column<&Contact<double>::normal_sigma>,
          "(N,) angular standard deviations of the normals [rad]; 0 where not stated")
      .def_property_readonly("footprint_sigmas", &contact_column<&Contact<double>::footprint_sigma>,
                             "(N,) footprints across the normals [m]; 0: all scatter")
      .def(py::pickle(
          [](const ContactList& cs) {
            // Version 1: one row of 20 per contact: position (3), covariance (9, row-major),
            // has a normal (1), normal (3), pressure, time, normal_sigma, footprint_sigma.
            ArrayD rows({static_cast<py::ssize_t>(cs.size()), py::ssize_t{kContactRow}});
            double* p = rows.mutable_data();
            for (const auto& c : cs) {
              store(p, c.position);
              store(p + 3, c.covariance);
              p[12] = c.normal ? 1.0 : 0.0;
              store(p + 13, c.normal.value_or(Vec3d::Zero()));
              p[16] = c.pressure;
              p[17] = c.time;
              p[18] = c.normal_sigma;
              p[19] = c.footprint_sigma;
              p += kContactRow;
            }
            return py::make_tuple(1, rows);
          },
          [](const py::tuple& t) {
            if (t.size() != 2 || t[0].cast<int>() != 1) {
              throw py::value_error("Contacts: not a pickled state of version 1");
            }
            const auto rows = t[1].cast<ArrayD>();
            require_shape(rows, {-1, kContactRow}, "pickled contacts", "(N, 20)");
            ContactList cs(static_cast<std::size_t>(rows.shape(0)));
            const double* p = rows.data();
            for (auto& c : cs) {
              c.position = Eigen::Map<const Vec3d>(p);
              c.covariance = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(p + 3);
              if (p[12] != 0.0) c.normal = Eigen::Map<const Vec3d>(p + 13);
              c.pressure = p[16];
              c.time = p[17];
              c.normal_sigma = p[18];
              c.footprint_sigma = p[19];
              p += kContactRow;
            }
            return cs;
          }))
      .def(
          "__deepcopy__", [](const ContactList& cs, const py::dict&) { return ContactList(cs); },
          py::arg("memo"))
      .def("__repr__",
           [](const ContactList& cs) { return "Contacts(" + std::to_string(cs.size()) + ")"; });
}

}  // namespace taxel::python
