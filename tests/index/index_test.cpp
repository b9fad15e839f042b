// SPDX-License-Identifier: MIT
// Law suite of taxel::index: every index answers exactly like BruteForce after streams of
// inserts, moves and erases, with ties broken by id.
#include <catch2/catch.hpp>
#include <random>
#include <taxel/index.hpp>
#include <vector>

namespace ti = taxel::index;

namespace {

constexpr double kRadius = 2e-3;

// VoxelHash with its cell table as full as allowed: long probe runs, wrap-around.
template <class S>
struct PackedVoxelHash : ti::VoxelHash<S> {
  explicit PackedVoxelHash(S radius) : ti::VoxelHash<S>(radius, {.max_load_factor = 0.9}) {}
};

template <class I>
I make_index() {
  if constexpr (std::is_constructible_v<I, typename I::Scalar>) {
    return I(static_cast<typename I::Scalar>(kRadius));
  } else {
    return I();
  }
}

// Compares every kind of query at q between `index` and the oracle.
template <class I, class S>
void expect_same_answers(const I& index, const ti::BruteForce<S>& oracle, const taxel::Vec3<S>& q) {
  for (const double rr : {0.0, 0.5 * kRadius, kRadius, 3.7 * kRadius}) {
    const S r = static_cast<S>(rr);
    const auto a = index.nearest_within(q, r);
    const auto b = oracle.nearest_within(q, r);
    REQUIRE(a.has_value() == b.has_value());
    if (a) {
      CHECK(a->id == b->id);
      CHECK(a->squared_distance == b->squared_distance);
    }
    CHECK(index.within(q, r) == oracle.within(q, r));
  }
  for (const std::size_t k : {std::size_t{1}, std::size_t{4}, oracle.size() + 3}) {
    CHECK(index.knn(q, k) == oracle.knn(q, k));
  }
}

template <class S>
taxel::Vec3<S> jitter(std::mt19937& rng, const taxel::Vec3<S>& c, double scale) {
  std::normal_distribution<double> g(0.0, scale);
  return (c.template cast<double>() + Eigen::Vector3d(g(rng), g(rng), g(rng))).template cast<S>();
}

}  // namespace

TEMPLATE_TEST_CASE("every incremental index matches BruteForce after inserts, moves and erases",
                   "[index]", ti::VoxelHash<float>, ti::VoxelHash<double>, PackedVoxelHash<double>,
                   ti::DynamicKdTree<float>, ti::DynamicKdTree<double>) {
  using I = TestType;
  using S = typename I::Scalar;
  using V = taxel::Vec3<S>;
  STATIC_REQUIRE(ti::IncrementalIndex<I>);

  // Origin-centred, negative and far-away (1 km) neighbourhoods.
  const double offset = GENERATE(0.0, -0.05, 1e3);
  std::mt19937 rng(static_cast<unsigned>(1234 + offset));
  const V centre = V::Constant(static_cast<S>(offset));

  I index = make_index<I>();
  ti::BruteForce<S> oracle;

  SECTION("an empty index answers nothing") {
    CHECK_FALSE(index.nearest_within(centre, S(1)).has_value());
    CHECK(index.knn(centre, 3).empty());
    CHECK(index.within(centre, S(1)).empty());
    CHECK(index.size() == 0);
  }

  SECTION("a single point, and duplicates, tie by id") {
    index.insert(7, centre);
    oracle.insert(7, centre);
    expect_same_answers(index, oracle, centre);
    index.insert(3, centre);
    oracle.insert(3, centre);
    index.insert(5, centre);
    oracle.insert(5, centre);
    const auto n = index.nearest_within(centre, S(kRadius));
    REQUIRE(n);
    CHECK(n->id == 3);
    expect_same_answers(index, oracle, centre);
    expect_same_answers(index, oracle, jitter(rng, centre, kRadius));
  }

  SECTION("points on cell boundaries") {
    const S cell = static_cast<S>(4 * kRadius);
    for (int i = -3; i <= 3; ++i) {
      for (int j = -3; j <= 3; ++j) {
        const V p = centre + V(S(i) * cell / 2, S(j) * cell / 2, S(0));
        const auto id = static_cast<ti::PointId>((i + 3) * 7 + (j + 3));
        index.insert(id, p);
        oracle.insert(id, p);
      }
    }
    for (int i = -4; i <= 4; ++i) {
      const V q = centre + V(S(i) * cell / 4, S(i % 3) * cell / 2, S(0));
      expect_same_answers(index, oracle, q);
    }
  }

  SECTION("random streams of inserts, moves and erases") {
    std::vector<V> where;
    std::vector<bool> alive;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int step = 0; step < 3000; ++step) {
      const double a = u(rng);
      if (a < 0.35 || oracle.size() < 5) {
        const auto id = static_cast<ti::PointId>(where.size());
        const V p = jitter(rng, centre, 0.01);
        index.insert(id, p);
        oracle.insert(id, p);
        where.push_back(p);
        alive.push_back(true);
      } else {
        auto id = static_cast<ti::PointId>(u(rng) * double(where.size()));
        while (!alive[id]) id = (id + 1) % static_cast<ti::PointId>(where.size());
        if (a < 0.85) {  // small moves, as in fusion, and occasional jumps
          const V p = jitter(rng, where[id], a < 0.8 ? 0.3 * kRadius : 0.01);
          index.move(id, p);
          oracle.move(id, p);
          where[id] = p;
        } else if (a < 0.92) {
          index.erase(id);
          oracle.erase(id);
          alive[id] = false;
        } else {  // a duplicate of a stored point
          const auto dup = static_cast<ti::PointId>(where.size());
          index.insert(dup, where[id]);
          oracle.insert(dup, where[id]);
          where.push_back(where[id]);
          alive.push_back(true);
        }
      }
      REQUIRE(index.size() == oracle.size());
      if (step % 25 == 0) {
        expect_same_answers(index, oracle, jitter(rng, centre, 0.01));
        expect_same_answers(index, oracle, where[step % where.size()]);
      }
    }
    for (std::size_t id = 0; id < where.size(); ++id)
      CHECK(index.contains(static_cast<ti::PointId>(id)) == alive[id]);
    index.clear();
    CHECK(index.size() == 0);
    CHECK_FALSE(index.nearest_within(centre, S(1)).has_value());
    index.insert(0, centre);
    CHECK(index.nearest_within(centre, S(0))->id == 0);
  }
}

TEMPLATE_TEST_CASE("KdTree matches BruteForce on a fixed cloud", "[index]", float, double) {
  using S = TestType;
  using V = taxel::Vec3<S>;
  STATIC_REQUIRE(ti::SpatialIndex<ti::KdTree<S>>);
  std::mt19937 rng(99);
  std::vector<V> pts;
  for (int i = 0; i < 2000; ++i) pts.push_back(jitter(rng, V(S(-1), S(2), S(0.5)), 0.02));
  pts.push_back(pts[10]);  // a duplicate: ties by id
  ti::BruteForce<S> oracle;
  for (std::size_t i = 0; i < pts.size(); ++i) oracle.insert(static_cast<ti::PointId>(i), pts[i]);
  const ti::KdTree<S> tree(pts);
  CHECK(tree.size() == pts.size());
  for (int t = 0; t < 100; ++t) expect_same_answers(tree, oracle, jitter(rng, pts[t * 7], kRadius));
  expect_same_answers(tree, oracle, pts[10]);
  CHECK(tree.nearest_within(pts[10], S(0))->id == 10);

  const ti::KdTree<S> empty(std::vector<V>{});
  CHECK_FALSE(empty.nearest_within(V::Zero(), S(1)).has_value());
  CHECK(empty.knn(V::Zero(), 2).empty());
}

TEST_CASE("indexes reject bad configuration and ignore non-finite queries", "[index]") {
  CHECK_THROWS_WITH(ti::VoxelHash<double>(0.0), Catch::Matchers::Contains("radius"));
  CHECK_THROWS_WITH(ti::VoxelHash<double>(std::nan("")), Catch::Matchers::Contains("radius"));
  CHECK_THROWS_WITH(ti::VoxelHash<double>(1e-3, {.max_load_factor = 1.5}),
                    Catch::Matchers::Contains("max_load_factor"));
  CHECK_THROWS_WITH(ti::DynamicKdTree<double>({.leaf_size = 0}),
                    Catch::Matchers::Contains("leaf_size"));
  CHECK_THROWS_WITH(ti::KdTree<double>(std::vector<taxel::Vec3d>{{0, 0, std::nan("")}}),
                    Catch::Matchers::Contains("point 0"));
  ti::VoxelHash<double> v(1e-3);
  v.insert(0, {0, 0, 0});
  const taxel::Vec3d bad(std::nan(""), 0, 0);
  CHECK_FALSE(v.nearest_within(bad, 1.0).has_value());
  CHECK(v.knn(bad, 1).empty());
  CHECK(v.within(bad, 1.0).empty());
  CHECK_FALSE(v.nearest_within({0, 0, 0}, -1.0).has_value());
  CHECK_THROWS_AS(v.insert(0, {1, 1, 1}), taxel::AssertionError);
  CHECK_THROWS_AS(v.move(5, {1, 1, 1}), taxel::AssertionError);
}

TEST_CASE("VoxelHash keeps a dense cell exact when it overflows its first block", "[index]") {
  ti::VoxelHash<double> v(1e-3);
  ti::BruteForce<double> oracle;
  std::mt19937 rng(5);
  for (ti::PointId i = 0; i < 200; ++i) {  // 200 points in one 2 mm cell
    const taxel::Vec3d p = jitter(rng, taxel::Vec3d(5e-4, 5e-4, 5e-4), 1e-4);
    v.insert(i, p);
    oracle.insert(i, p);
  }
  for (ti::PointId i = 0; i < 200; i += 3) {  // empty some blocks, forcing unlinks
    v.erase(i);
    oracle.erase(i);
  }
  for (ti::PointId i = 1; i < 200; i += 3) {
    const taxel::Vec3d p = jitter(rng, taxel::Vec3d(5e-3, 0, 0), 1e-4);  // move them away
    v.move(i, p);
    oracle.move(i, p);
  }
  for (int t = 0; t < 20; ++t) {
    expect_same_answers(v, oracle, jitter(rng, taxel::Vec3d(2e-3, 2e-4, 2e-4), 2e-3));
  }
}

TEST_CASE("UniformGrid refuses clouds too wide to grid and survives huge coordinates",
          "[index][reliability]") {
  using G = ti::UniformGrid<double>;
  // The extent overflows to infinity: refused at once (this construction used to loop forever).
  CHECK_THROWS_WITH(G({{-1e308, 0, 0}, {1e308, 0, 0}}), Catch::Matchers::Contains("too wide"));
  CHECK_THROWS_WITH(ti::UniformGrid<float>({{-3e38f, 0, 0}, {3e38f, 0, 0}}),
                    Catch::Matchers::Contains("too wide"));
  // Wide but legal: one tight cluster and one point 1e30 m away. Cells stay within int range
  // and queries stay exact against brute force.
  std::vector<taxel::Vec3<double>> pts;
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  for (int i = 0; i < 200; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
  pts.emplace_back(1e30, -1e30, 1e30);
  const G grid(pts);
  ti::BruteForce<double> brute;
  for (std::size_t i = 0; i < pts.size(); ++i) brute.insert(static_cast<ti::PointId>(i), pts[i]);
  for (const taxel::Vec3<double>& q :
       {taxel::Vec3<double>(0, 0, 0), taxel::Vec3<double>(1e29, -1e29, 1e29),
        taxel::Vec3<double>(-1e20, 1e20, 0), taxel::Vec3<double>(5e-4, 0, -5e-4)}) {
    const auto a = grid.nearest_within(q, std::numeric_limits<double>::infinity());
    const auto b = brute.nearest_within(q, std::numeric_limits<double>::infinity());
    REQUIRE(a.has_value() == b.has_value());
    if (a) CHECK(a->id == b->id);
  }
  // A squared distance that overflows is no distance: neither the grid nor brute force return
  // such a point, even for r = infinity (found by fuzz_geometry: they used to disagree).
  const std::vector<taxel::Vec3<double>> far{{3e-4, -9.6e303, 1e-284}};
  const G far_grid(far);
  ti::BruteForce<double> far_brute;
  far_brute.insert(0, far[0]);
  const double inf = std::numeric_limits<double>::infinity();
  CHECK_FALSE(far_grid.nearest_within({0, 0, 0}, inf).has_value());
  CHECK_FALSE(far_brute.nearest_within({0, 0, 0}, inf).has_value());
  CHECK(far_grid.nearest_within({0, -9.6e303, 0}, inf).has_value());
  // All points equal: a valid grid of one occupied cell.
  const G same(std::vector<taxel::Vec3<double>>(5, taxel::Vec3<double>(1, 2, 3)));
  CHECK(same.nearest_within({1, 2, 3}, 0.0).has_value());
}

TEST_CASE("VoxelHash refuses radii a cell cannot represent and states its exact range",
          "[index][reliability]") {
  CHECK_THROWS_WITH(ti::VoxelHash<double>(1e-310), Catch::Matchers::Contains("radius"));
  CHECK_THROWS_WITH(ti::VoxelHash<float>(1e-39f), Catch::Matchers::Contains("radius"));
  CHECK_THROWS_WITH(ti::VoxelHash<double>(1e308), Catch::Matchers::Contains("radius"));
  const ti::VoxelHash<double> h(2e-3);
  // 2^30 - 2 cells of 2 r (1 + 1e-4): about 4.3 million metres from the origin.
  CHECK(h.max_coordinate() == Approx((1073741824.0 - 2.0) * 4e-3 * (1 + 1e-4)));
}
