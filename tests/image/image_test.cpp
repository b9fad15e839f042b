// SPDX-License-Identifier: MIT
// Tests of taxel::image against MATLAB's published regionprops values (MathWorks' documentation),
// the Sobel test vector, exhaustive k-means, brute-force flood fills and closed forms.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <taxel/image.hpp>
#include <vector>

#include "support/allocation_counter.hpp"

namespace ti = taxel::image;
using taxel_test::g_allocations;

namespace {

ti::Mask mask_from(std::initializer_list<const char*> rows) {
  const auto nr = static_cast<Eigen::Index>(rows.size());
  const auto nc = static_cast<Eigen::Index>(std::strlen(*rows.begin()));
  ti::Mask m(nr, nc);
  Eigen::Index r = 0;
  for (const char* s : rows) {
    for (Eigen::Index c = 0; c < nc; ++c) m(r, c) = s[c] == '1' ? 1 : 0;
    ++r;
  }
  return m;
}

ti::Mask sample() {
  return mask_from({"000000000101100000", "000000001111000000", "000000001110000000",
                    "000000001110000000", "000000111111000000", "000000111111111110",
                    "000000111111111110", "101001101100111110", "011111110110001111",
                    "011001110000000011"});
}

constexpr double kTol = 1e-9;

}  // namespace

TEST_CASE("regionprops: MATLAB's values for scikit-image's SAMPLE", "[image]") {
  const ti::Mask m = sample();
  ti::RegionAnalyzer a({}, m.rows(), m.cols());
  const ti::RegionProps& p = a.compute(m);
  CHECK(p.area == 72);
  CHECK(p.centroid.x() == Approx(10.444444444444445).epsilon(kTol));
  CHECK(p.centroid.y() == Approx(6.666666666666667).epsilon(kTol));
  CHECK(p.bounding_box == Eigen::Vector4d(0.5, 0.5, 18, 10));
  CHECK(p.major_axis == Approx(16.83207712478172).epsilon(kTol));
  CHECK(p.minor_axis == Approx(9.807515103475811).epsilon(kTol));
  CHECK(p.eccentricity == Approx(0.8127101798028248).epsilon(kTol));
  CHECK(p.orientation == Approx(5.985601077838894).epsilon(kTol));
  CHECK(p.convex_area == 124);
  CHECK(p.solidity == Approx(0.580645161290323).epsilon(kTol));
  CHECK(p.extent == Approx(0.4).epsilon(kTol));
  CHECK(p.equiv_diameter == Approx(9.57461472963).epsilon(1e-11));
  CHECK(p.euler_number == 0);
  CHECK(p.euler_number4 == 2);

  const ti::Mask convex_image = mask_from(
      {"000000000111100000", "000000001111110000", "000000111111111000", "000001111111111000",
       "000011111111111100", "001111111111111110", "011111111111111110", "111111111111111111",
       "011111111111111111", "011111111111111111"});
  CHECK((a.convex_image() == convex_image).all());

  // 0-based coordinates shift centroid and box by one.
  const ti::RegionProps z = ti::region_props(m, {.zero_based = true});
  CHECK(z.centroid.x() == Approx(9.444444444444445).epsilon(kTol));
  CHECK(z.bounding_box(0) == -0.5);

  // The transpose turns the orientation.
  const ti::Mask t = m.transpose();
  CHECK(ti::region_props(t).orientation == Approx(84.0143989221611).epsilon(kTol));
}

TEST_CASE("regionprops: MATLAB's values for SAMPLE_mod (one hole)", "[image]") {
  ti::Mask m = sample();
  m(7, 15) = 0;
  const ti::RegionProps p = ti::region_props(m);
  CHECK(p.area == 71);
  CHECK(p.centroid.x() == Approx(10.366197183098592).epsilon(kTol));
  CHECK(p.centroid.y() == Approx(6.647887323943662).epsilon(kTol));
  CHECK(p.major_axis == Approx(16.75381941360563).epsilon(kTol));
  CHECK(p.minor_axis == Approx(9.831773172456037).epsilon(kTol));
  CHECK(p.eccentricity == Approx(0.8097045704033392).epsilon(kTol));
  CHECK(p.orientation == Approx(6.715887428026976).epsilon(kTol));
  CHECK(p.convex_area == 124);
  CHECK(p.euler_number == -1);
  CHECK(p.euler_number4 == 1);
}

TEST_CASE("regionprops: Octave's MATLAB-compatibility vectors", "[image]") {
  const ti::RegionProps eye = ti::region_props(mask_from({"1000", "0100", "0010", "0001"}));
  CHECK(eye.major_axis == Approx(6.4291).epsilon(1e-4));
  CHECK(eye.minor_axis == Approx(1.1547).epsilon(1e-4));
  CHECK(eye.eccentricity == Approx(0.98374).epsilon(1e-5));
  CHECK(eye.orientation == Approx(-45).epsilon(kTol));
  CHECK(eye.equiv_diameter == Approx(2.2568).epsilon(1e-4));

  const ti::RegionProps ones = ti::region_props(ti::Mask::Ones(5, 5));
  CHECK(ones.major_axis == Approx(5.7735).epsilon(1e-4));
  CHECK(ones.minor_axis == Approx(5.7735).epsilon(1e-4));
  CHECK(ones.eccentricity == Approx(0).margin(kTol));
  CHECK(ones.orientation == 0);

  const ti::RegionProps tri = ti::region_props(mask_from({"001", "011", "110"}));
  CHECK(tri.major_axis == Approx(4.1633).epsilon(1e-4));
  CHECK(tri.minor_axis == Approx(1.8037).epsilon(1e-4));
  CHECK(tri.eccentricity == Approx(0.90128).epsilon(1e-5));
  CHECK(tri.orientation == Approx(45).epsilon(kTol));

  const ti::RegionProps dot = ti::region_props(mask_from({"000", "010", "000"}));
  CHECK(dot.major_axis == Approx(1.1547005383792517).epsilon(kTol));
  CHECK(dot.minor_axis == Approx(1.1547005383792517).epsilon(kTol));
  CHECK(dot.orientation == 0);
  CHECK(dot.convex_area == 1);
  CHECK(dot.perimeter == 0);
  CHECK(dot.euler_number == 1);

  const ti::RegionProps bar = ti::region_props(mask_from({"11111"}));
  CHECK(bar.orientation == 0);
  CHECK(bar.major_axis == Approx(5.773502691896258).epsilon(kTol));
  CHECK(bar.minor_axis == Approx(1.1547005383792528).epsilon(kTol));
  CHECK(bar.eccentricity == Approx(0.9797958971132712).epsilon(kTol));
  CHECK(bar.convex_area == 5);
  const ti::Mask vertical = mask_from({"11111"}).transpose();
  CHECK(ti::region_props(vertical).orientation == 90);
}

TEST_CASE("regionprops: perimeter of rectangles in closed form, empty regions", "[image]") {
  for (int h = 2; h <= 6; ++h) {
    for (int w = 2; w <= 7; ++w) {
      ti::Mask m = ti::Mask::Zero(h + 4, w + 3);
      m.block(2, 1, h, w).setOnes();
      const double steps = 2.0 * (w - 1 + h - 1);
      CHECK(ti::region_props(m).perimeter == Approx(0.980 * steps - 0.091 * 4).epsilon(kTol));
    }
  }
  // Two disjoint rectangles add up; the diagonal step of a 2-pixel staircase is odd.
  ti::Mask two = ti::Mask::Zero(8, 12);
  two.block(1, 1, 2, 3).setOnes();
  two.block(5, 6, 3, 4).setOnes();
  const double expect = (0.980 * 6 - 0.364) + (0.980 * 10 - 0.364);
  CHECK(ti::region_props(two).perimeter == Approx(expect).epsilon(kTol));

  const ti::RegionProps empty = ti::region_props(ti::Mask::Zero(4, 4));
  CHECK(empty.area == 0);
  CHECK(empty.convex_area == 0);
  CHECK(empty.centroid.isZero());
  CHECK(empty.convex_hull.empty());
  CHECK(ti::region_props(ti::Mask(0, 0)).area == 0);
}

namespace {

// Independent oracle: union-find over pixel pairs.
struct Dsu {
  std::vector<int> p;
  explicit Dsu(int n) : p(static_cast<std::size_t>(n)) { std::iota(p.begin(), p.end(), 0); }
  int find(int x) {
    return p[static_cast<std::size_t>(x)] == x
               ? x
               : p[static_cast<std::size_t>(x)] = find(p[static_cast<std::size_t>(x)]);
  }
  void join(int a, int b) { p[static_cast<std::size_t>(find(a))] = find(b); }
};

// Components of (mask == value) on a padded frame when `pad`, by union-find.
int count_components(const ti::Mask& m, std::uint8_t value, bool eight, bool pad) {
  const Eigen::Index o = pad ? 1 : 0;
  const Eigen::Index rows = m.rows() + 2 * o, cols = m.cols() + 2 * o;
  auto at = [&](Eigen::Index r, Eigen::Index c) -> std::uint8_t {
    r -= o;
    c -= o;
    if (r < 0 || c < 0 || r >= m.rows() || c >= m.cols()) return 0;
    return m(r, c) != 0 ? 1 : 0;
  };
  Dsu d(static_cast<int>(rows * cols));
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      if (at(r, c) != value) continue;
      for (const auto& [dr, dc] : {std::pair{0, 1}, {1, 0}, {1, 1}, {1, -1}}) {
        if (!eight && dr != 0 && dc != 0) continue;
        const Eigen::Index rr = r + dr, cc = c + dc;
        if (rr < rows && cc >= 0 && cc < cols && at(rr, cc) == value) {
          d.join(static_cast<int>(r * cols + c), static_cast<int>(rr * cols + cc));
        }
      }
    }
  }
  int n = 0;
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) {
      const int i = static_cast<int>(r * cols + c);
      n += at(r, c) == value && d.find(i) == i ? 1 : 0;
    }
  }
  return n;
}

ti::Mask random_mask(std::mt19937& rng, Eigen::Index rows, Eigen::Index cols, double fill) {
  std::bernoulli_distribution b(fill);
  ti::Mask m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = b(rng) ? 1 : 0;
  return m;
}

}  // namespace

TEST_CASE("components agree with a union-find oracle, bwareaopen", "[image]") {
  std::mt19937 rng(7);
  ti::Components comp;
  for (int trial = 0; trial < 300; ++trial) {
    // Up to 64 columns the rows are labelled as runs of bits, wider masks pixel by pixel.
    const Eigen::Index rows = 1 + trial % 13;
    const Eigen::Index cols = 1 + (trial * 7) % 17 + (trial % 4 == 0 ? 50 : 0);
    const ti::Mask m = random_mask(rng, rows, cols, 0.3 + 0.4 * (trial % 3) / 2.0);
    for (const auto conn : {ti::Connectivity::four, ti::Connectivity::eight}) {
      const bool eight = conn == ti::Connectivity::eight;
      const int n = comp.compute(m, conn);
      REQUIRE(n == count_components(m, 1, eight, false));
      // Same label <=> connected: labels agree with adjacency, and the areas sum up.
      long total = 0;
      for (int id = 1; id <= n; ++id) total += comp.area(id);
      CHECK(total == (m != 0).count());
      for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c + 1 < cols; ++c) {
          if (m(r, c) && m(r, c + 1)) CHECK(comp.labels()(r, c) == comp.labels()(r, c + 1));
        }
      }
      // bwareaopen keeps exactly the components with at least P pixels.
      const int p = 1 + trial % 6;
      ti::Mask opened = m;
      const int kept = ti::remove_small_regions(opened, p, conn);
      int expect = 0;
      for (int id = 1; id <= n; ++id) expect += comp.area(id) >= p ? 1 : 0;
      CHECK(kept == expect);
      ti::Components after;
      CHECK(after.compute(opened, conn) == expect);
      CHECK(((opened != 0) <= (m != 0)).all());
    }
  }
}

TEST_CASE("components: full rows and stripes at the 64-column word boundary", "[image]") {
  ti::Components comp;
  for (const Eigen::Index cols : {62, 63, 64, 65}) {
    for (int pattern = 0; pattern < 4; ++pattern) {
      ti::Mask m(5, cols);
      for (Eigen::Index r = 0; r < m.rows(); ++r) {
        for (Eigen::Index c = 0; c < cols; ++c) {
          const bool on = pattern == 0   ? true                         // all set
                          : pattern == 1 ? (r + c) % 2 == 0             // checkerboard
                          : pattern == 2 ? c == cols - 1 || r % 2 == 0  // comb
                                         : c % 3 != 1;                  // stripes
          m(r, c) = on ? 1 : 0;
        }
      }
      for (const auto conn : {ti::Connectivity::four, ti::Connectivity::eight}) {
        const bool eight = conn == ti::Connectivity::eight;
        CHECK(comp.compute(m, conn) == count_components(m, 1, eight, false));
        long total = 0;
        for (int id = 1; id <= comp.count(); ++id) total += comp.area(id);
        CHECK(total == (m != 0).count());
      }
    }
  }
}

TEST_CASE("region descriptors agree with brute force on random masks", "[image]") {
  std::mt19937 rng(11);
  ti::RegionAnalyzer a({}, 16, 16);
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Index rows = 1 + trial % 11, cols = 1 + (trial * 5) % 14;
    const ti::Mask m = random_mask(rng, rows, cols, 0.15 + 0.7 * (trial % 4) / 3.0);
    const ti::RegionProps& p = a.compute(m);
    const double n = static_cast<double>((m != 0).count());
    REQUIRE(p.area == n);
    if (n == 0) continue;
    double sx = 0, sy = 0;
    Eigen::Index r0 = rows, r1 = -1, c0 = cols, c1 = -1;
    for (Eigen::Index r = 0; r < rows; ++r) {
      for (Eigen::Index c = 0; c < cols; ++c) {
        if (!m(r, c)) continue;
        sx += static_cast<double>(c + 1);
        sy += static_cast<double>(r + 1);
        r0 = std::min(r0, r), r1 = std::max(r1, r), c0 = std::min(c0, c), c1 = std::max(c1, c);
      }
    }
    CHECK(p.centroid.x() == Approx(sx / n));
    CHECK(p.centroid.y() == Approx(sy / n));
    CHECK(p.bounding_box ==
          Eigen::Vector4d(static_cast<double>(c0) + 0.5, static_cast<double>(r0) + 0.5,
                          static_cast<double>(c1 - c0 + 1), static_cast<double>(r1 - r0 + 1)));
    // Euler number = objects - holes (holes are background components of the padded image
    // other than the outside, with the complementary connectivity).
    CHECK(p.euler_number ==
          count_components(m, 1, true, false) - (count_components(m, 0, false, true) - 1));
    CHECK(p.euler_number4 ==
          count_components(m, 1, false, false) - (count_components(m, 0, true, true) - 1));
    CHECK(p.major_axis >= p.minor_axis);
    CHECK(p.orientation >= -90);
    CHECK(p.orientation <= 90);

    // ConvexArea lies between the pixel centres well inside the hull and those inside or near
    // it: poly2mask snaps vertices to a 1/5-pixel grid (moving edges by up to 0.1 px) and drops
    // some centres on slanted edges. Every region pixel is inside.
    const auto& hull = p.convex_hull;
    int strict = 0, closed = 0;
    for (Eigen::Index r = r0; r <= r1; ++r) {
      for (Eigen::Index c = c0; c <= c1; ++c) {
        const Eigen::Vector2d q(static_cast<double>(c + 1), static_cast<double>(r + 1));
        double min_cross = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < hull.size() && hull.size() >= 3; ++i) {
          const Eigen::Vector2d e = hull[(i + 1) % hull.size()] - hull[i];
          const Eigen::Vector2d v = q - hull[i];
          min_cross = std::min(min_cross, (e.x() * v.y() - e.y() * v.x()) / e.norm());
        }
        // Hull vertices run counter-clockwise on screen (y down): inside means cross >= 0.
        strict += min_cross > 0.15 ? 1 : 0;
        closed += min_cross > -0.15 ? 1 : 0;
        if (m(r, c)) CHECK(a.convex_image()(r - r0, c - c0) == 1);
      }
    }
    CHECK(p.convex_area >= strict);
    CHECK(p.convex_area <= closed);
    CHECK(p.convex_area >= n);
  }
}

TEST_CASE("region descriptors: the packed-row path equals the byte path", "[image]") {
  // Masks up to 62 columns are analysed as 64-bit rows; wider ones byte by byte. The same
  // region inside a mask widened with empty columns must give the same descriptors.
  std::mt19937 rng(23);
  ti::RegionAnalyzer narrow({}, 40, 62), wide({}, 40, 90);
  for (int trial = 0; trial < 300; ++trial) {
    const Eigen::Index rows = 1 + trial % 37, cols = 1 + (trial * 11) % 62;
    const ti::Mask m = random_mask(rng, rows, cols, 0.05 + 0.9 * (trial % 7) / 6.0);
    ti::Mask w = ti::Mask::Zero(rows, 90);
    w.leftCols(cols) = m;
    if (trial % 3 == 0) w.leftCols(cols) *= 7;  // any non-zero value is inside
    const ti::RegionProps& a = narrow.compute(m);
    const ti::RegionProps& b = wide.compute(w);
    REQUIRE(a.area == b.area);
    CHECK(a.centroid == b.centroid);
    CHECK(a.bounding_box == b.bounding_box);
    CHECK(a.major_axis == b.major_axis);
    CHECK(a.minor_axis == b.minor_axis);
    CHECK(a.orientation == b.orientation);
    CHECK(a.euler_number == b.euler_number);
    CHECK(a.euler_number4 == b.euler_number4);
    CHECK(a.convex_area == b.convex_area);
    CHECK(a.convex_hull == b.convex_hull);
    CHECK(a.perimeter == Approx(b.perimeter).margin(1e-12));
    CHECK((narrow.convex_image() == wide.convex_image()).all());
  }
  // Row packing of arbitrary byte values, against one bit per byte.
  for (int trial = 0; trial < 200; ++trial) {
    std::uniform_int_distribution<int> byte(0, 255), zero(0, 2);
    std::vector<std::uint8_t> row(64);
    for (auto& v : row) v = zero(rng) == 0 ? 0 : static_cast<std::uint8_t>(byte(rng));
    const Eigen::Index cols = trial % 65;
    std::uint64_t expect = 0;
    for (Eigen::Index c = 0; c < cols; ++c) {
      expect |= std::uint64_t{row[static_cast<std::size_t>(c)] != 0} << c;
    }
    CHECK(ti::detail::pack_row(row.data(), cols) == expect);
  }
}

TEST_CASE("fast_atan2 agrees with std::atan2", "[image]") {
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> sobel(-1020, 1020), expo(-300, 300);
  double worst = 0.0;
  for (int i = 0; i < 400000; ++i) {
    double y = 0, x = 0;
    switch (i % 4) {
      case 0:
        y = u(rng), x = u(rng);
        break;
      case 1:
        y = sobel(rng), x = sobel(rng);
        break;  // the recognizer's inputs
      case 2:
        y = std::ldexp(u(rng), expo(rng)), x = std::ldexp(u(rng), expo(rng));
        break;
      default:
        y = u(rng) * 1e-3, x = u(rng);
        break;  // near the axes
    }
    const double a = ti::detail::fast_atan2(y, x), b = std::atan2(y, x);
    worst = std::max(worst, std::abs(a - b));
    if (std::abs(a - b) > 1e-15) FAIL_CHECK("atan2(" << y << ", " << x << ") " << a << " vs " << b);
  }
  CHECK(worst < 1e-15);
  // Signed zeros, axes and the non-finite cases take std::atan2's values exactly.
  const double inf = std::numeric_limits<double>::infinity();
  for (const double y : {0.0, -0.0, 1.0, -1.0, inf, -inf}) {
    for (const double x : {0.0, -0.0, 1.0, -1.0, inf, -inf}) {
      const double a = ti::detail::fast_atan2(y, x), b = std::atan2(y, x);
      CHECK(a == b);
      CHECK(std::signbit(a) == std::signbit(b));
    }
  }
  CHECK(std::isnan(ti::detail::fast_atan2(std::nan(""), 1.0)));
}

TEST_CASE("gradient_magnitude equals imgradient's magnitude, borders included", "[image]") {
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> u(-50.0, 300.0);
  for (const auto& [rows, cols] : {std::pair<Eigen::Index, Eigen::Index>{1, 1},
                                   {1, 7},
                                   {7, 1},
                                   {2, 2},
                                   {2, 5},
                                   {3, 3},
                                   {5, 2},
                                   {32, 32},
                                   {14, 6},
                                   {9, 40}}) {
    ti::ImageD img(rows, cols);
    for (Eigen::Index i = 0; i < img.size(); ++i) img.data()[i] = std::round(u(rng));
    ti::ImageD fast, mag, dir;
    ti::gradient_magnitude(img, fast);
    ti::gradient(img, mag, dir);
    REQUIRE(fast.rows() == rows);
    REQUIRE(fast.cols() == cols);
    for (Eigen::Index i = 0; i < img.size(); ++i) {
      CHECK(fast.data()[i] == Approx(mag.data()[i]).epsilon(1e-14).margin(1e-12));
    }
  }
}

TEST_CASE("Sobel gradients match MATLAB's imgradient test vector", "[image]") {
  ti::ImageD img(3, 3);
  img << 1, 2, 3, 4, 5, 6, 7, 8, 9;
  ti::ImageD gx, gy, mag, dir;
  ti::sobel(img, gx, gy);
  CHECK(gx(1, 1) == 8);
  CHECK(gy(1, 1) == 24);
  CHECK(gx(0, 0) == 4);
  CHECK(gy(0, 0) == 12);
  CHECK(gx(0, 1) == 8);
  CHECK(gy(0, 1) == 12);
  ti::gradient(img, mag, dir);
  CHECK(mag(1, 1) == Approx(25.298221).epsilon(1e-7));
  CHECK(dir(1, 1) == Approx(-71.565051).epsilon(1e-7));
  CHECK(mag(0, 1) == Approx(14.422205).epsilon(1e-7));
  CHECK(dir(0, 1) == Approx(-56.309932).epsilon(1e-7));
  // A 1x1 image: replicate border, zero gradient.
  ti::ImageD one = ti::ImageD::Constant(1, 1, 5.0);
  ti::sobel(one, gx, gy);
  CHECK(gx(0, 0) == 0);
  CHECK(gy(0, 0) == 0);

  ti::Mask out;
  ti::contour(mask_from({"0000", "0111", "0111", "0111"}), out);
  CHECK(out.cast<int>().sum() == 8);
  CHECK(out(2, 2) == 0);
  CHECK(out(3, 2) == 1);  // image border counts as outside
}

namespace {
// Exhaustive optimum of 1-D k-means with contiguous clusters of the sorted values.
double exhaustive_sse(std::vector<double> v, int k) {
  std::sort(v.begin(), v.end());
  const int n = static_cast<int>(v.size());
  double best = std::numeric_limits<double>::infinity();
  std::vector<int> cut(static_cast<std::size_t>(k - 1));
  // Enumerate cut positions 0 < c1 < c2 < ... < n.
  std::function<void(int, int)> rec = [&](int idx, int start) {
    if (idx == k - 1) {
      double sse = 0;
      int lo = 0;
      for (int j = 0; j < k; ++j) {
        const int hi = j == k - 1 ? n : cut[static_cast<std::size_t>(j)];
        double s = 0;
        for (int i = lo; i < hi; ++i) s += v[static_cast<std::size_t>(i)];
        const double mean = s / (hi - lo);
        for (int i = lo; i < hi; ++i) {
          sse += (v[static_cast<std::size_t>(i)] - mean) * (v[static_cast<std::size_t>(i)] - mean);
        }
        lo = hi;
      }
      best = std::min(best, sse);
      return;
    }
    for (int c = start; c <= n - (k - 1 - idx); ++c) {
      cut[static_cast<std::size_t>(idx)] = c;
      rec(idx + 1, c + 1);
    }
  };
  rec(0, 1);
  return best;
}
}  // namespace

TEST_CASE("k-means: the DP optimum equals exhaustive search, histogram path agrees", "[image]") {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 500; ++trial) {
    const int n = 1 + trial % 11;
    const int k = 1 + trial % 4;
    std::vector<double> v(static_cast<std::size_t>(n));
    std::uniform_int_distribution<int> level(0, trial % 2 == 0 ? 6 : 255);
    for (double& x : v) x = level(rng);
    const ti::KMeans1dResult r = ti::kmeans1d(v, k);
    REQUIRE(r.ok());
    std::vector<double> distinct = v;
    std::sort(distinct.begin(), distinct.end());
    distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
    const int keff = std::min<int>(k, static_cast<int>(distinct.size()));
    REQUIRE(r.k == keff);
    CHECK(r.message.empty() == (keff == k));
    CHECK(r.sse == Approx(exhaustive_sse(v, keff)).margin(1e-9));
    CHECK(std::is_sorted(r.centroids.begin(), r.centroids.end()));
    std::size_t total = 0;
    for (std::size_t s : r.sizes) total += s;
    CHECK(total == v.size());
    for (double x : v) {
      const int c = r.cluster_of(x);
      CHECK(x >= r.lower[static_cast<std::size_t>(c)]);
      CHECK(x <= r.upper[static_cast<std::size_t>(c)]);
    }
    // Histogram of integer levels gives the same clustering.
    std::vector<std::uint32_t> hist(256, 0);
    for (double x : v) ++hist[static_cast<std::size_t>(x)];
    ti::KMeans1d solver(k);
    const ti::KMeans1dResult& h = solver.fit_histogram(hist);
    CHECK(h.sse == Approx(r.sse).margin(1e-9));
    CHECK(h.centroids == r.centroids);
    // Lloyd is a local optimum: never better than the exact one.
    const ti::KMeans1dResult l = ti::kmeans1d_lloyd(v, {.k = k, .seed = 5});
    CHECK(l.sse >= r.sse - 1e-9);
  }
  // Bad input is reported, not a crash.
  CHECK(ti::kmeans1d(std::vector<double>{}, 3).status == taxel::Status::invalid_input);
  CHECK(ti::kmeans1d(std::vector<double>{1, std::nan(""), 2}, 3).status ==
        taxel::Status::invalid_input);
  CHECK_THROWS_AS(ti::KMeans1d(0), std::invalid_argument);
  // Well-separated data: Lloyd finds the optimum too.
  std::vector<double> sep;
  for (int i = 0; i < 30; ++i) sep.push_back(10.0 * (i % 3) + 0.01 * i);
  const auto exact = ti::kmeans1d(sep, 3);
  const auto lloyd = ti::kmeans1d_lloyd(sep, {.k = 3, .seed = 9});
  CHECK(lloyd.sse == Approx(exact.sse));
  CHECK(exact.centroids[1] == Approx(10.145));
}

namespace {
// A 32x32 palm-like image: background 0, a low-pressure palm (80), and inside it either a
// sharp high-pressure band (an edge, 220) or a gentle bump (edgeless, +20 at the centre).
ti::ImageD palm_image(bool sharp_edge) {
  ti::ImageD img = ti::ImageD::Zero(32, 32);
  for (int r = 4; r < 28; ++r) {
    for (int c = 3; c < 29; ++c) {
      if (sharp_edge) {
        img(r, c) = r >= 12 && r < 20 && c >= 8 && c < 24 ? 220 : 80;
      } else {
        img(r, c) = std::round(
            80 + 20 * std::exp(-((r - 15.5) * (r - 15.5) + (c - 15.5) * (c - 15.5)) / 72.0));
      }
    }
  }
  return img;
}
}  // namespace

TEST_CASE("k-means: few and many distinct values (hash merge and sort) both exact", "[image]") {
  // Up to n / 4 + 16 distinct values are merged through a hash table, more by sorting; both
  // must give the exhaustive optimum and the histogram path's clustering.
  std::mt19937 rng(41);
  for (int trial = 0; trial < 12; ++trial) {
    const std::size_t n = 120 + 20 * static_cast<std::size_t>(trial);
    const int levels = trial % 3 == 0 ? 5 : trial % 3 == 1 ? 40 : 5000;  // few .. all distinct
    std::uniform_int_distribution<int> level(0, levels - 1);
    std::vector<double> v(n);
    for (double& x : v) x = level(rng);
    for (const int k : {2, 3}) {
      ti::KMeans1d solver(k, n);
      const ti::KMeans1dResult r = solver.fit(v);
      REQUIRE(r.ok());
      if (n <= 200) CHECK(r.sse == Approx(exhaustive_sse(v, r.k)).margin(1e-9));
      std::vector<std::uint32_t> hist(static_cast<std::size_t>(levels), 0);
      for (double x : v) ++hist[static_cast<std::size_t>(x)];
      ti::KMeans1d by_hist(k);
      const ti::KMeans1dResult& h = by_hist.fit_histogram(hist);
      CHECK(h.centroids == r.centroids);
      CHECK(h.sizes == r.sizes);
      CHECK(h.sse == Approx(r.sse).margin(1e-9));
      // Scaled to non-integers (a calibrated sensor): the same partition.
      std::vector<double> scaled = v;
      for (double& x : scaled) x = 0.0137 * x + 0.001;
      const ti::KMeans1dResult sc = solver.fit(scaled);
      CHECK(sc.sizes == r.sizes);
    }
  }
  // -0 and +0 are one value.
  const ti::KMeans1dResult z = ti::kmeans1d(std::vector<double>{-0.0, 0.0, 0.0, 5.0, 9.0}, 3);
  CHECK(z.k == 3);
  CHECK(z.sizes[0] == 3);
}

TEST_CASE("segmentation: classes, polarity, small regions, degenerate images", "[image]") {
  const ti::ImageD img = palm_image(true);
  const ti::Segmentation s = ti::segment(img);
  REQUIRE(s.ok());
  CHECK(s.kmeans.k == 3);
  CHECK(s.classes(0, 0) == 0);
  CHECK(s.classes(5, 5) == 1);
  CHECK(s.classes(15, 10) == 2);
  CHECK(s.regions == 1);
  CHECK(s.high.cast<int>().sum() == 8 * 16);
  CHECK(s.high_level == Approx(220));
  CHECK(s.quantised(5, 5) == Approx(80));

  // Dark-is-pressure: the inverted image segments identically.
  const ti::ImageD inverted = 255.0 - img;
  const ti::Segmentation d = ti::segment(inverted, {.polarity = ti::Polarity::dark_is_pressure});
  CHECK((d.classes == s.classes).all());
  CHECK(d.high_level == Approx(35));

  // Non-integer values take the sorting path and agree.
  const ti::Segmentation f = ti::segment(img * 0.5 + 0.25);
  CHECK((f.classes == s.classes).all());
  CHECK(s.pixel_min == img.minCoeff());
  CHECK(s.pixel_max == img.maxCoeff());
  CHECK(s.pixel_mean == Approx(img.mean()).epsilon(1e-14));

  // Integer images, negative ones too, take the histogram path; it agrees with sorting.
  std::mt19937 rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    std::uniform_int_distribution<int> level(-300 + 7 * trial, 200 + 40 * trial);
    ti::ImageD q(32, 32);
    for (Eigen::Index i = 0; i < q.size(); ++i) q.data()[i] = level(rng);
    for (const auto pol : {ti::Polarity::high_is_pressure, ti::Polarity::dark_is_pressure}) {
      const ti::Segmentation h = ti::segment(q, {.polarity = pol, .min_area = 3});
      const ti::Segmentation v =
          ti::segment(q, {.polarity = pol, .min_area = 3, .histogram_levels = 0});
      REQUIRE(h.ok());
      CHECK(h.kmeans.centroids == v.kmeans.centroids);
      CHECK((h.classes == v.classes).all());
      CHECK((h.quantised == v.quantised).all());
      CHECK((h.high == v.high).all());
      CHECK(h.regions == v.regions);
    }
  }

  // A patch smaller than min_area disappears.
  ti::ImageD small = palm_image(false);
  small.block(1, 1, 3, 3).setConstant(250);
  const ti::Segmentation sm = ti::segment(small, {.min_area = 50});
  CHECK(sm.high_raw(2, 2) == 1);
  CHECK(sm.high(2, 2) == 0);

  // Degenerate images.
  const ti::Segmentation zero = ti::segment(ti::ImageD::Zero(32, 32));
  CHECK(zero.ok());
  CHECK(zero.kmeans.k == 1);
  CHECK_FALSE(zero.message.empty());
  CHECK((zero.classes == 0).all());
  CHECK(zero.regions == 0);
  const ti::Segmentation two = ti::segment([] {
    ti::ImageD t = ti::ImageD::Zero(32, 32);
    t.block(0, 0, 10, 10).setConstant(9);
    return t;
  }());
  CHECK(two.kmeans.k == 2);
  CHECK(two.classes(0, 0) == 2);
  CHECK(two.regions == 1);
  ti::ImageD one_pixel = ti::ImageD::Zero(32, 32);
  one_pixel(3, 4) = 100;
  const ti::Segmentation op = ti::segment(one_pixel);
  CHECK(op.high_raw(3, 4) == 1);
  CHECK(op.regions == 0);  // removed: 1 px < 50
  ti::ImageD bad = img;
  bad(2, 3) = std::nan("");
  const ti::Segmentation b = ti::segment(bad);
  CHECK(b.status == taxel::Status::invalid_input);
  CHECK(b.message.find("(2, 3)") != std::string::npos);
  CHECK(ti::segment(ti::ImageD(0, 0)).status == taxel::Status::invalid_input);
  ti::ImageD huge = img;
  huge(0, 0) = 1e194;  // found by fuzz_image_readers: would overflow sums of squares
  CHECK(ti::segment(huge).status == taxel::Status::invalid_input);
  CHECK_THROWS_AS(ti::Segmenter({.k = 1}), std::invalid_argument);
  CHECK_THROWS_AS(ti::Segmenter({.min_area = -1}), std::invalid_argument);
}

TEST_CASE("reconstruction: RecEdged plateau, RecEdgeless recovers polynomials", "[image]") {
  // RecEdged: rows with more low than high pressure raise the level (the text's rule).
  const ti::ImageD img = palm_image(true);
  const ti::Segmentation s = ti::segment(img);
  ti::Reconstructor rec({.k = 0.5}, {}, 32, 32);
  const ti::ImageD& h = rec.rec_edged(s);
  CHECK(h(0, 5) == 0);                   // mostly background row: skipped
  CHECK(h(5, 5) == Approx(0.5 * 220));   // low > high: raised to T1 = K I2
  CHECK(h(5, 0) == 0);                   // background pixel of a contact row stays 0
  CHECK(h(14, 5) == 0);                  // high > low: lowered by T2
  CHECK(h(22, 5) == Approx(0.5 * 220));  // raised again
  ti::Reconstructor whole({.k = 1.0, .fill_whole_row = true}, {}, 32, 32);
  CHECK(whole.rec_edged(s)(5, 0) == Approx(220));
  ti::Reconstructor swapped({.k = 1.0, .swap_edge_condition = true}, {}, 32, 32);
  CHECK(swapped.rec_edged(s)(5, 5) == 0);
  // A row with more high than low pressure ends the raised part under the text's rule.
  ti::ImageD wide = img;
  wide.block(12, 3, 8, 26).setConstant(220);
  const ti::Segmentation ws = ti::segment(wide);
  ti::Reconstructor text_rule({.k = 1.0}, {}, 32, 32);
  const ti::ImageD& hw = text_rule.rec_edged(ws);
  CHECK(hw(5, 5) == Approx(220));
  CHECK(hw(14, 5) == 0);
  CHECK(hw(22, 5) == Approx(220));
  ti::Reconstructor smooth({.k = 1.0, .postprocess = ti::PostProcess::mean3x3}, {}, 32, 32);
  CHECK(smooth.rec_edged(s)(4, 5) < 220);

  // RecEdgeless: a quadratic column profile with finger gaps is recovered exactly.
  ti::ImageD q = ti::ImageD::Zero(32, 32);
  for (int r = 6; r < 26; ++r) {
    for (int c = 4; c < 28; ++c) q(r, c) = 200 - 0.4 * (r - 15) * (r - 15) + 0.5 * c;
  }
  for (int r = 6; r < 12; ++r) q(r, 10) = 0;  // a finger gap, healed from its neighbours
  for (int r = 6; r < 26; ++r) q(r, 20) = 0;  // a mostly-background column: removed
  const ti::Segmentation qs = ti::segment(q, {.min_area = 0});
  ti::Reconstructor e({}, {.degree = 2}, 32, 32);
  const ti::ImageD& hq = e.rec_edgeless(q, qs);
  CHECK(hq(0, 0) == 0);  // removed rows stay zero
  for (int r = 6; r < 26; ++r) {
    CHECK(hq(r, 20) == 0);
    for (int c = 4; c < 28; ++c) {
      if (c == 20) continue;
      CHECK(hq(r, c) == Approx(200 - 0.4 * (r - 15) * (r - 15) + 0.5 * c).margin(1e-9));
    }
  }
  // All background: an all-zero map, no crash.
  const ti::Segmentation zs = ti::segment(ti::ImageD::Zero(32, 32));
  CHECK(e.rec_edgeless(ti::ImageD::Zero(32, 32), zs).isZero());
  CHECK(rec.rec_edged(zs).isZero());
  CHECK_THROWS_AS(ti::Reconstructor({}, {.degree = 9}), std::invalid_argument);
  CHECK_THROWS_AS(ti::Reconstructor({.background_fraction = 2}, {}), std::invalid_argument);
  // The step factor: within +-1e6, so that heights and their gradients stay finite.
  for (const double k : {1e300, -1e300, 1.000001e6, std::numeric_limits<double>::quiet_NaN(),
                         std::numeric_limits<double>::infinity()}) {
    CHECK_THROWS_WITH(ti::Reconstructor({.k = k}, {}),
                      Catch::Contains("RecEdgedConfig::k must be in [-1e6, 1e6]"));
  }
  // At the bounds, on pixels at the largest magnitude segmentation accepts: finite heights,
  // and a recogniser's hybrid features (gradient magnitudes of those heights) finite too.
  ti::ImageD big = ti::ImageD::Zero(32, 32);
  big.block(8, 4, 16, 24).setConstant(1e100);
  big.block(12, 8, 8, 16).setConstant(0.5e100);
  const ti::Segmentation bs = ti::segment(big, {.min_area = 0});
  REQUIRE(bs.ok());
  for (const double k : {1e6, -1e6}) {
    for (const auto pp : {ti::PostProcess::none, ti::PostProcess::mean3x3}) {
      ti::Reconstructor at_bound({.k = k, .background_fraction = 1.0, .postprocess = pp}, {}, 32,
                                 32);
      const ti::ImageD& heights = at_bound.rec_edged(bs);
      CHECK(heights.allFinite());
      CHECK(heights.cwiseAbs().maxCoeff() > 1e105);  // the steps were taken
      ti::RecognizerConfig rc;
      rc.segmentation.min_area = 0;
      rc.edged = {.k = k, .background_fraction = 1.0, .postprocess = pp};
      ti::Recognizer<> recognizer(32, 32, rc, ti::GradientThreshold{-1.0});  // always edged
      const ti::Recognition& r = recognizer.recognize(big);
      REQUIRE(r.ok());
      CHECK(r.edged);
      CHECK(r.hybrid.allFinite());
    }
  }
}

TEST_CASE("Recognizer: features, edged decision, no allocation per image", "[image]") {
  ti::Recognizer<> rec(32, 32);
  const ti::Recognition& sharp = rec.recognize(palm_image(true));
  REQUIRE(sharp.ok());
  CHECK(sharp.regional(0) == 8 * 16);
  CHECK(sharp.edge_features(11) == 220);
  CHECK(sharp.edge_features(12) == 0);
  CHECK(sharp.edge_features(14) == 8 * 16);
  CHECK(sharp.edge_features(15) == 0);  // only one HPR: zero-padded
  CHECK(sharp.contour_gradient > 25);
  CHECK(sharp.edged);
  CHECK(sharp.hybrid.size() == 1035);
  CHECK(sharp.hybrid.tail<11>() == sharp.regional);
  CHECK(sharp.label == -1);
  const bool sharp_edged = sharp.edged;

  const ti::Recognition& soft = rec.recognize(palm_image(false));
  REQUIRE(soft.ok());
  CHECK(soft.contour_gradient < 25);
  CHECK_FALSE(soft.edged);
  CHECK(sharp_edged != soft.edged);

  // Bad inputs.
  ti::ImageD bad = palm_image(true);
  bad(0, 0) = std::numeric_limits<double>::infinity();
  CHECK(rec.recognize(bad).status == taxel::Status::invalid_input);
  CHECK(rec.recognize(ti::ImageD::Zero(8, 8)).status == taxel::Status::invalid_input);
  CHECK(rec.recognize(ti::ImageD::Zero(32, 32)).ok());
  CHECK(rec.result().hybrid.isZero());

  if (TAXEL_TEST_COUNTS_ALLOCATIONS) {
    const ti::ImageD a = palm_image(true), b = palm_image(false);
    rec.recognize(a);
    rec.recognize(b);
    const long before = g_allocations.load();
    for (int i = 0; i < 20; ++i) rec.recognize(i % 2 ? a : b);
    CHECK(g_allocations.load() - before == 0);
  }
}

TEST_CASE("Image types refuse negative and huge sizes before allocating", "[image][reliability]") {
  using Catch::Matchers::Contains;
  CHECK_THROWS_WITH(ti::Recognizer<>(-1, 32), Contains("Recognizer") && Contains("-1 x 32"));
  CHECK_THROWS_WITH(ti::Recognizer<>(32, 0), Contains(">= 1"));
  CHECK_THROWS_WITH(ti::Recognizer<>(1 << 20, 1 << 20), Contains("at most 16777216 pixels"));
  CHECK_THROWS_WITH(ti::Segmenter({}, -5, -5), Contains("Segmenter"));
  CHECK_THROWS_WITH(ti::RegionAnalyzer({}, 32, -1), Contains("RegionAnalyzer"));
  CHECK_THROWS_WITH(ti::Reconstructor({}, {}, -3, 4), Contains("Reconstructor"));
  CHECK_THROWS_WITH(ti::Components(-1, -1), Contains("Components"));
  CHECK_THROWS_WITH(ti::KMeans1d(3, static_cast<std::size_t>(-1)), Contains("KMeans1d"));
  // The largest legal size still works for a tiny image.
  CHECK_NOTHROW(ti::Recognizer<>(1, 1));
}

TEST_CASE("recognize_all on several threads equals one Recognizer run in order",
          "[image][threads]") {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 255.0);
  std::vector<ti::ImageD> imgs;
  for (int k = 0; k < 23; ++k) {  // blobs of varying size and place on noise
    ti::ImageD img(32, 32);
    for (Eigen::Index r = 0; r < 32; ++r) {
      for (Eigen::Index c = 0; c < 32; ++c) {
        const double d =
            std::hypot(static_cast<double>(r - 8 - k % 11), static_cast<double>(c - 10 - k % 7));
        img(r, c) = (d < 4.0 + k % 5 ? 200.0 : 10.0) + 0.05 * u(rng);
      }
    }
    imgs.push_back(img);
  }
  imgs[7](3, 3) = std::numeric_limits<double>::quiet_NaN();  // one failure, kept in its slot
  const ti::Recognizer<> proto(32, 32);
  ti::Recognizer<> seq = proto;
  const auto at = [&](std::size_t i) -> const ti::ImageD& { return imgs[i]; };
  for (const unsigned threads : {1u, 2u, 5u, 0u}) {
    const std::vector<ti::Recognition> all = ti::recognize_all(proto, imgs.size(), at, threads);
    REQUIRE(all.size() == imgs.size());
    for (std::size_t i = 0; i < imgs.size(); ++i) {
      const ti::Recognition& one = seq.recognize(imgs[i]);
      CHECK(all[i].status == one.status);
      CHECK(all[i].hybrid == one.hybrid);
      CHECK(all[i].edge_features == one.edge_features);
      CHECK(all[i].edged == one.edged);
    }
  }
  CHECK(ti::recognize_all(proto, 0, at, 2).empty());
}
