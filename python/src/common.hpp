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
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/core/status.hpp"
#include "taxel/core/types.hpp"

namespace taxel::python {

namespace py = pybind11;

/// A C-contiguous numpy array of T taken strictly, by the one conversion every argument of the
/// module goes through: a C-contiguous array of T is taken as it is (no copy); another array,
/// or a list, is converted when its values are real numbers (bool, integer or floating dtypes;
/// strings, complex numbers, dates and objects raise TypeError) and, for an integer T, when
/// every value is a whole number in T's range (100.7, NaN, -1 for uint16, 65536 + v, 2^33 for
/// int32 raise ValueError naming the value and its index), never truncated or wrapped.
template <class T>
class StrictArray : public py::array_t<T, py::array::c_style | py::array::forcecast> {
 public:
  using Base = py::array_t<T, py::array::c_style | py::array::forcecast>;
  using Base::Base;
  StrictArray() = default;
  StrictArray(Base&& a) : Base(std::move(a)) {}  // NOLINT: implicit, as array_t's own
};
using ArrayD = StrictArray<double>;
using ArrayI = StrictArray<int>;
using ArrayI64 = StrictArray<std::int64_t>;
using ArrayU16 = StrictArray<std::uint16_t>;
using ArrayU8 = StrictArray<std::uint8_t>;

namespace detail {

/// The numpy name of a dtype ("<U3", "complex128").
inline std::string dtype_name(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

/// "(i, j)" of the flat C-order index `k` of `a`.
inline std::string index_text(const py::array& a, py::ssize_t k) {
  std::string out;
  for (py::ssize_t d = a.ndim(); d-- > 0;) {
    const py::ssize_t n = a.shape(d) > 0 ? a.shape(d) : 1;
    out = std::to_string(k % n) + (out.empty() ? "" : ", ") + out;
    k /= n;
  }
  return "[" + out + "]";
}

/// Converts `src` for StrictArray<T> (see there); throws TypeError or ValueError.
template <class T>
StrictArray<T> strict_array(py::handle src) {
  using Base = typename StrictArray<T>::Base;
  py::array a = py::array::ensure(src);
  if (!a) throw py::type_error("expected an array of numbers");
  const char kind = a.dtype().kind();
  if (kind != 'b' && kind != 'i' && kind != 'u' && kind != 'f') {
    throw py::type_error("expected an array of real numbers, got an array of dtype " +
                         dtype_name(a));
  }
  if constexpr (std::is_integral_v<T>) {
    if (!a.dtype().is(py::dtype::of<T>()) && kind != 'b') {
      constexpr auto lo = static_cast<long double>(std::numeric_limits<T>::min());
      constexpr auto hi = static_cast<long double>(std::numeric_limits<T>::max());
      const std::string range = std::to_string(std::numeric_limits<T>::min()) + ", " +
                                std::to_string(std::numeric_limits<T>::max());
      const auto refuse = [&](py::ssize_t k, const std::string& value) {
        throw py::value_error("expected whole numbers in [" + range + "], got " + value + " at " +
                              index_text(a, k));
      };
      if (kind == 'f') {
        const auto d = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t k = 0; k < d.size(); ++k) {
          const double v = d.data()[k];
          if (!(std::isfinite(v) && v == std::floor(v) && v >= lo && v <= hi)) {
            refuse(k, py::repr(py::float_(v)).cast<std::string>());
          }
        }
      } else if (kind == 'u') {
        const auto u =
            py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t k = 0; k < u.size(); ++k) {
          if (static_cast<long double>(u.data()[k]) > hi) refuse(k, std::to_string(u.data()[k]));
        }
      } else {
        const auto i =
            py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t k = 0; k < i.size(); ++k) {
          const auto v = static_cast<long double>(i.data()[k]);
          if (v < lo || v > hi) refuse(k, std::to_string(i.data()[k]));
        }
      }
    }
  }
  Base out = Base::ensure(a);
  if (!out) throw py::error_already_set();
  return StrictArray<T>(std::move(out));
}

}  // namespace detail

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

/// The reader-writer lock of the bound C++ object at `object`. Methods that release the GIL
/// take it after releasing the GIL (exclusively when they change the object, shared when they
/// read it), and so do the methods that touch the object with the GIL held; a thread holding
/// it never waits for the GIL. So two Python threads may share one object: their calls on it
/// run one at a time (reads together). The locks are striped over the objects' addresses: two
/// objects may share one, which only serialises them.
inline std::shared_mutex& object_mutex(const void* object) {
  static std::shared_mutex stripes[64];
  return stripes[(reinterpret_cast<std::uintptr_t>(object) >> 4) % 64];
}
/// An exclusive lock on `object` (see object_mutex).
inline std::unique_lock<std::shared_mutex> write_lock(const void* object) {
  return std::unique_lock<std::shared_mutex>(object_mutex(object));
}
/// A shared lock on `object` (see object_mutex).
inline std::shared_lock<std::shared_mutex> read_lock(const void* object) {
  return std::shared_lock<std::shared_mutex>(object_mutex(object));
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

/// A read-only (N, 3) array over 3-vectors held by the Python object `owner`, which the array
/// keeps alive: no copy. Only for objects that Python cannot change (PointCloud).
template <class Vectors>
py::array readonly_points(const Vectors& v, py::handle owner) {
  static_assert(sizeof(typename Vectors::value_type) == 3 * sizeof(double));
  py::array_t<double> out({static_cast<py::ssize_t>(v.size()), py::ssize_t{3}},
                          {py::ssize_t{3 * sizeof(double)}, py::ssize_t{sizeof(double)}},
                          v.empty() ? nullptr : v.data()->data(), owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

/// A read-only 1-D array over a vector held by `owner` (see readonly_points).
template <class T>
py::array readonly_vector(const std::vector<T>& v, py::handle owner) {
  py::array_t<T> out({static_cast<py::ssize_t>(v.size())}, {py::ssize_t{sizeof(T)}}, v.data(),
                     owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

namespace detail {
template <class V>
py::object pickled(const V& v) {
  if constexpr (std::is_enum_v<V>) {
    return py::int_(static_cast<long long>(v));
  } else if constexpr (std::is_same_v<V, Isometry3d>) {
    return py::cast(Eigen::Matrix4d(v.matrix()));
  } else {
    return py::cast(v);
  }
}
template <class V>
void unpickled(V& v, const py::handle& h) {
  if constexpr (std::is_enum_v<V>) {
    v = static_cast<V>(h.cast<long long>());
  } else if constexpr (std::is_same_v<V, Isometry3d>) {
    v.matrix() = h.cast<Eigen::Matrix4d>();
  } else {
    v = h.cast<V>();
  }
}
}  // namespace detail

/// Pickling (state: version 1, then the members in order) and deep copies for a C++ struct
/// whose members are all listed; `name` is the class's Python name, for errors.
template <class T, class... Ms>
void pickle_members(py::class_<T>& cls, const char* name, Ms... members) {
  cls.def(py::pickle(
      [members...](const T& t) { return py::make_tuple(1, detail::pickled(t.*members)...); },
      [members..., name](const py::tuple& s) {
        if (s.size() != sizeof...(Ms) + 1 || s[0].cast<int>() != 1) {
          throw py::value_error(std::string(name) + ": not a pickled state of version 1");
        }
        T t{};
        std::size_t i = 1;
        (detail::unpickled(t.*members, s[i++]), ...);
        return t;
      }));
  cls.def(
      "__deepcopy__", [](const T& t, const py::dict&) { return T(t); }, py::arg("memo"));
}

/// Pickling through a constructor: `args(t)` gives the arguments as a tuple, `make(tuple)`
/// builds the object again; deep copies copy.
/// `Copy` false: copy.deepcopy goes through the pickled state (for a type whose copy
/// constructor is declared but cannot be instantiated, such as one holding a vector of
/// unique_ptr).
template <bool Copy = true, class T, class Args, class Make>
void pickle_with(py::class_<T>& cls, const char* name, Args args, Make make) {
  cls.def(py::pickle([args](const T& t) { return py::make_tuple(1, args(t)); },
                     [make, name](const py::tuple& s) {
                       if (s.size() != 2 || s[0].cast<int>() != 1) {
                         throw py::value_error(std::string(name) +
                                               ": not a pickled state of version 1");
                       }
                       return make(s[1].cast<py::tuple>());
                     }));
  if constexpr (Copy && std::is_copy_constructible_v<T>) {
    cls.def(
        "__deepcopy__", [](const T& t, const py::dict&) { return T(t); }, py::arg("memo"));
  }  // else copy.deepcopy goes through the pickled state
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
void bind_index(py::module_& m);
void bind_registration(py::module_& m);
void bind_image(py::module_& m);
void bind_learn(py::module_& m);
void bind_io(py::module_& m);
void bind_sim(py::module_& m);
void bind_shape(py::module_& m);
void bind_optical(py::module_& m);

}  // namespace taxel::python

namespace pybind11::detail {
/// Arguments of type StrictArray<T> go through taxel::python::detail::strict_array.
// The enable_if form of pybind11's own caster for Python object types, more specialised.
template <class T>
struct type_caster<taxel::python::StrictArray<T>,
                   enable_if_t<is_pyobject<taxel::python::StrictArray<T>>::value>> {
  using Array = taxel::python::StrictArray<T>;
  PYBIND11_TYPE_CASTER(Array, handle_type_name<typename Array::Base>::name);
  bool load(handle src, bool convert) {
    if (!convert) {  // the no-conversion pass: exactly an array of T, C-contiguous
      if (!Array::Base::check_(src)) return false;
      value = reinterpret_borrow<typename Array::Base>(src);
      return true;
    }
    // Neither an array nor a sequence: another overload may take it.
    if (!isinstance<array>(src) && !isinstance<sequence>(src)) return false;
    if (isinstance<str>(src) || isinstance<bytes>(src)) return false;
    value = taxel::python::detail::strict_array<T>(src);
    return true;
  }
  static handle cast(const Array& src, return_value_policy, handle) { return src.inc_ref(); }
};
}  // namespace pybind11::detail

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
  double footprint_sigma = 0.0;  // every row's Contact::footprint_sigma

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
    c.footprint_sigma = footprint_sigma;
    return c;
  }
};

/// Checks the arrays' shapes against each other; throws ValueError naming the one that differs.
ContactRows contact_rows(ArrayD positions, std::optional<ArrayD> covariances,
                         std::optional<ArrayD> normals, std::optional<ArrayD> pressures,
                         std::optional<ArrayD> times, std::optional<double> sigma,
                         double footprint_sigma);

}  // namespace taxel::python
