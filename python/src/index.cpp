// SPDX-License-Identifier: MIT
// taxel.index: k-nearest and radius queries over a fixed point set (KdTree, on nanoflann), in
// the shape of scipy.spatial.cKDTree's answers.
#include "common.hpp"
#include "index_queries.hpp"
#include "taxel/index/kdtree.hpp"

namespace taxel::python {
namespace {

/// The Python KdTree: the tree and its build option.
struct PyKdTree {
  index::KdTree<double> tree;
  std::size_t leaf_size;
};

PyKdTree make_tree(const ArrayD& points, std::size_t leaf_size) {
  if (leaf_size == 0) throw py::value_error("KdTree: leaf_size must be >= 1");
  std::vector<Vec3d> pts = points_from(points, "points");
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!pts[i].allFinite()) {
      throw py::value_error("KdTree: point " + std::to_string(i) + " is not finite");
    }
  }
  py::gil_scoped_release release;
  return PyKdTree{index::KdTree<double>(std::move(pts), {leaf_size}), leaf_size};
}

}  // namespace

void bind_index(py::module_& root) {
  py::module_ m = root.def_submodule("index", R"doc(
Nearest-neighbour queries over 3-D points [m]: ``KdTree`` over a fixed set (nanoflann), and
the same queries on a ``taxel.fusion.ContactCloud``'s incremental index. Answers are exact,
ordered by distance with ties by id, and shaped as scipy.spatial.cKDTree's: ``query`` gives
(distances, ids), with distance inf and id n where fewer than k points exist.)doc");

  py::class_<PyKdTree> cls(m, "KdTree", R"doc(
A static kd-tree over (N, 3) points [m] (nanoflann), for k-nearest and radius queries.
Immutable: queries from several threads at once are safe, and release the GIL.)doc");
  pickle_with(
      cls, "KdTree",
      [](const PyKdTree& t) { return py::make_tuple(points_array(t.tree.points()), t.leaf_size); },
      [](const py::tuple& a) {
        if (a.size() != 2) throw py::value_error("KdTree: damaged pickled state");
        return make_tree(a[0].cast<ArrayD>(), a[1].cast<std::size_t>());
      });
  cls.def(py::init(&make_tree), py::arg("points"), py::kw_only(), py::arg("leaf_size") = 10,
          "Builds the tree over (N, 3) finite points [m]; ValueError naming a point that is "
          "not finite.")
      .def("__len__", [](const PyKdTree& t) { return t.tree.size(); })
      .def("__repr__",
           [](const PyKdTree& t) {
             return "KdTree(" + std::to_string(t.tree.size()) +
                    " points, leaf_size=" + std::to_string(t.leaf_size) + ")";
           })
      .def_property_readonly(
          "points",
          [](const py::object& self) -> ArrayD {
            return readonly_points(self.cast<const PyKdTree&>().tree.points(), self);
          },
          "(N, 3) points [m], a read-only view")
      .def_readonly("leaf_size", &PyKdTree::leaf_size, "the most points a leaf holds")
      .def(
          "query",
          [](const PyKdTree& t, const ArrayD& x, std::size_t k) {
            return knn_query(x, k, t.tree.size(),
                             [&](const Vec3d& q, std::size_t kk) { return t.tree.knn(q, kk); });
          },
          py::arg("x"), py::arg("k") = 1, kQueryDoc)
      .def(
          "query_ball_point",
          [](const PyKdTree& t, const ArrayD& x, double r) {
            return radius_query(x, r,
                                [&](const Vec3d& q, double rr) { return t.tree.within(q, rr); });
          },
          py::arg("x"), py::arg("r"), kBallDoc);
}

}  // namespace taxel::python
