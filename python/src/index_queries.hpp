// SPDX-License-Identifier: MIT
// k-nearest and radius queries over any taxel index, answered in cKDTree's shapes: shared by
// taxel.index.KdTree and taxel.fusion.ContactCloud.
#pragma once

#include <limits>
#include <vector>

#include "common.hpp"
#include "taxel/index/concepts.hpp"

namespace taxel::python {

inline constexpr const char* kQueryDoc =
    "The k nearest points to each row of x (M, 3) [m]: (distances, ids), each (M,) for k = 1 "
    "and (M, k) otherwise, nearest first, ties by id. Where fewer than k points exist the "
    "distance is inf and the id is len(self), as scipy's cKDTree gives them. A query row that "
    "is not finite finds nothing. Releases the GIL.";
inline constexpr const char* kBallDoc =
    "The points within distance r [m] of each row of x (M, 3): a list of M int64 arrays of "
    "ids, nearest first, ties by id (cKDTree's query_ball_point, whose lists are unordered). "
    "Releases the GIL.";

/// (distances, ids) for each query row: `knn(q, k)` gives a row's neighbours, nearest first;
/// `n` is the number of points (the id of a missing neighbour).
template <class Knn>
py::tuple knn_query(const ArrayD& x, std::size_t k, std::size_t n, Knn&& knn) {
  require_shape(x, {-1, 3}, "x", "(M, 3)");
  if (k == 0) throw py::value_error("query: k must be >= 1");
  const auto m = x.shape(0);
  const auto kk = static_cast<py::ssize_t>(k);
  std::vector<py::ssize_t> shape{m};
  if (k > 1) shape.push_back(kk);
  py::array_t<double> dist(shape);
  py::array_t<std::int64_t> ids(shape);
  {
    py::gil_scoped_release release;
    double* d = dist.mutable_data();
    std::int64_t* id = ids.mutable_data();
    for (py::ssize_t i = 0; i < m; ++i) {
      const Vec3d q(x.data()[3 * i], x.data()[3 * i + 1], x.data()[3 * i + 2]);
      const auto found = knn(q, k);
      for (std::size_t j = 0; j < k; ++j) {
        const bool hit = j < found.size();
        d[i * kk + static_cast<py::ssize_t>(j)] =
            hit ? std::sqrt(found[j].squared_distance) : std::numeric_limits<double>::infinity();
        id[i * kk + static_cast<py::ssize_t>(j)] =
            hit ? static_cast<std::int64_t>(found[j].id) : static_cast<std::int64_t>(n);
      }
    }
  }
  return py::make_tuple(dist, ids);
}

/// The ids within r of each query row, each row's nearest first.
template <class Within>
py::list radius_query(const ArrayD& x, double r, Within&& within) {
  require_shape(x, {-1, 3}, "x", "(M, 3)");
  if (!(r >= 0.0)) throw py::value_error("query_ball_point: r must be >= 0");
  std::vector<std::vector<index::Neighbor<double>>> found(static_cast<std::size_t>(x.shape(0)));
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < found.size(); ++i) {
      const Vec3d q(x.data()[3 * i], x.data()[3 * i + 1], x.data()[3 * i + 2]);
      found[i] = within(q, r);
    }
  }
  py::list out;
  for (const auto& f : found) {
    py::array_t<std::int64_t> ids(static_cast<py::ssize_t>(f.size()));
    for (std::size_t j = 0; j < f.size(); ++j) ids.mutable_data()[j] = f[j].id;
    out.append(ids);
  }
  return out;
}

}  // namespace taxel::python
