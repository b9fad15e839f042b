// SPDX-License-Identifier: MIT
// Shared helpers of the Python bindings: numpy arrays in and out, poses, names of enums.
#pragma once

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/core/status.hpp"
#include "taxel/core/types.hpp"

namespace taxel::python {

namespace py = pybind11;

/// A C-contiguous float64 array; other dtypes and layouts are converted (copied) on the way in,
/// a C-contiguous float64 array is taken as it is.
using ArrayD = py::array_t<double, py::array::c_style | py::array::forcecast>;
using ArrayI = py::array_t<int, py::array::c_style | py::array::forcecast>;
using ArrayU16 = py::array_t<std::uint16_t, py::array::c_style | py::array::forcecast>;
using ArrayU8 = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>;

inline std::string shape_text(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    if (i) s += ", ";
    s += std::to_string(a.shape(i));
  }
  if (a.ndim() == 1) s += ",";
  return s + ")";
}

/// Throws ValueError unless `a` has the given shape; -1 matches any length.
inline void require_shape(const py::array& a, std::initializer_list<py::ssize_t> shape,
                          const char* what, const char* expected) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  py::ssize_t i = 0;
  for (const py::ssize_t s : shape) {
    if (!ok) break;
    ok = s < 0 || a.shape(i) == s;
    ++i;
  }
  if (!ok) {
    throw py::value_error(std::string(what) + ": expected an array of shape " + expected +
                          ", got " + shape_text(a));
  }
}

/// Writes a 3-vector to out[0..3).
inline void store(double* out, const Vec3d& v) { Eigen::Map<Vec3d>{out} = v; }
/// Writes a 3x3 matrix to out[0..9), row-major.
inline void store(double* out, const Mat3d& m) {
  Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>{out} = m;
}

/// An (N, 3) array from 3-vectors.
template <class Vectors>
ArrayD points_array(const Vectors& v) {
  ArrayD out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}});
  double* p = out.mutable_data();
  for (const auto& x : v) {
    p[0] = x.x();
    p[1] = x.y();
    p[2] = x.z();
    p += 3;
  }
  return out;
}

/// 3-vectors from an (N, 3) array.
inline std::vector<Vec3d> points_from(const ArrayD& a, const char* what) {
  require_shape(a, {-1, 3}, what, "(N, 3)");
  std::vector<Vec3d> out(static_cast<std::size_t>(a.shape(0)));
  std::memcpy(static_cast<void*>(out.data()), a.data(), out.size() * 3 * sizeof(double));
  return out;
}

/// The row-major 4x4 matrix at `m` into `t`, and why it is not a rigid transform
/// (taxel::rigid_defect), or nullptr when it is.
inline const char* rigid_defect(const double* m, Isometry3d& t) {
  t.matrix() = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(m);
  return taxel::rigid_defect(t);
}

/// A 4x4 homogeneous matrix as an isometry; ValueError naming `what` unless it is rigid.
inline Isometry3d pose_from(const ArrayD& a, const char* what) {
  require_shape(a, {4, 4}, what, "(4, 4)");
  Isometry3d t = Isometry3d::Identity();
  if (const char* why = rigid_defect(a.data(), t)) {
    throw py::value_error(std::string(what) + ": " + why);
  }
  return t;
}

/// An isometry as a 4x4 array.
inline ArrayD pose_array(const Isometry3d& t) {
  ArrayD out({4, 4});
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out.mutable_data()[r * 4 + c] = t.matrix()(r, c);
  }
  return out;
}

/// A vector as a 1-D array.
template <class T>
py::array_t<T> vector_array(const std::vector<T>& v) {
  py::array_t<T> out(static_cast<py::ssize_t>(v.size()));
  if (!v.empty()) std::memcpy(out.mutable_data(), v.data(), v.size() * sizeof(T));
  return out;
}

/// Raises ValueError with the outcome's message unless `o` is ok (or, when `allow_not_converged`,
/// not_converged).
inline void raise_unless_ok(const Outcome& o, bool allow_not_converged = false) {
  if (o.ok() || (allow_not_converged && o.status == Status::not_converged)) return;
  throw py::value_error(o.message.empty() ? std::string(to_string(o.status)) : o.message);
}

/// The value of `name` among `names` (the enum's values in order), or ValueError listing them.
template <class E, std::size_t N>
E enum_from(std::string_view name, const std::pair<std::string_view, E> (&names)[N],
            const char* what) {
  // Appended piece by piece: GCC 12 at -O3 without LTO flags `"'" + std::string(n)` with a
  // bogus -Wrestrict (GCC bug 105329).
  std::string known;
  for (const auto& [n, e] : names) {
    if (n == name) return e;
    known.append(known.empty() ? "'" : ", '").append(n).append("'");
  }
  std::string message(what);
  message.append(": unknown value '").append(name).append("' (expected one of ").append(known);
  throw py::value_error(message.append(")"));
}

/// The name of `e` among `names`.
template <class E, std::size_t N>
std::string enum_name(E e, const std::pair<std::string_view, E> (&names)[N]) {
  for (const auto& [n, v] : names) {
    if (v == e) return std::string(n);
  }
  return "?";
}

/// A point cloud as the Python `PointCloud` holds it.
using Cloud = PointCloud<double>;

/// A cloud from points and optional normals and fields.
Cloud cloud_from(const ArrayD& points, const std::optional<ArrayD>& normals, const char* what);

/// Contacts in a C++ vector, shared with Python as `taxel.Contacts`.
using ContactList = std::vector<Contact<double>>;

void bind_core(py::module_& m);
void bind_fusion(py::module_& m);
void bind_registration(py::module_& m);
void bind_image(py::module_& m);
void bind_learn(py::module_& m);
void bind_io(py::module_& m);
void bind_sim(py::module_& m);

}  // namespace taxel::python

PYBIND11_MAKE_OPAQUE(taxel::python::ContactList)

namespace taxel::python {

/// Contacts given as numpy arrays, row by row, without copying the arrays (when they are
/// C-contiguous float64 already).
struct ContactRows {
  std::size_t n = 0;
  ArrayD positions;
  std::optional<ArrayD> covariances;  // (N, 3, 3) or one shared (3, 3)
  std::optional<ArrayD> normals;      // (N, 3); a NaN row means no normal
  std::optional<ArrayD> pressures;    // (N,)
  std::optional<ArrayD> times;        // (N,)
  Mat3d default_covariance = Contact<double>{}.covariance;

  /// Contact `i`. Safe without the GIL: only reads the arrays' buffers.
  Contact<double> at(std::size_t i) const {
    Contact<double> c;
    const double* p = positions.data() + 3 * i;
    c.position = Vec3d(p[0], p[1], p[2]);
    if (covariances) {
      const bool shared = covariances->ndim() == 2;
      const double* m = covariances->data() + (shared ? 0 : 9 * i);
      c.covariance = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(m);
    } else {
      c.covariance = default_covariance;
    }
    if (normals) {
      const double* q = normals->data() + 3 * i;
      if (!(std::isnan(q[0]) && std::isnan(q[1]) && std::isnan(q[2])))
        c.normal = Vec3d(q[0], q[1], q[2]);
    }
    if (pressures) c.pressure = pressures->data()[i];
    if (times) c.time = times->data()[i];
    return c;
  }
};

/// Checks the arrays' shapes against each other; throws ValueError naming the one that differs.
ContactRows contact_rows(ArrayD positions, std::optional<ArrayD> covariances,
                         std::optional<ArrayD> normals, std::optional<ArrayD> pressures,
                         std::optional<ArrayD> times, std::optional<double> sigma);

}  // namespace taxel::python
