// SPDX-License-Identifier: MIT
#include <catch2/catch.hpp>
#include <cmath>
#include <taxel/sim/palm_grasp.hpp>

using taxel::sim::GraspClass;
using taxel::sim::PalmGraspConfig;
using taxel::sim::PalmGraspSynth;

namespace {
// Mean of each image row over the columns with any pressure.
Eigen::VectorXd row_profile(const taxel::image::ImageD& img) {
  Eigen::VectorXd p(img.rows());
  for (Eigen::Index r = 0; r < img.rows(); ++r) p(r) = img.row(r).mean();
  return p;
}
}  // namespace

TEST_CASE("Palm-grasp images are seeded, deterministic and 8-bit", "[sim][palm_grasp]") {
  const PalmGraspSynth a({}, 7);
  const PalmGraspSynth b({}, 7);
  const PalmGraspSynth other({}, 8);
  const auto img = a.render(a.subject(3), GraspClass::two_edged, false, 4);
  CHECK(img.rows() == 32);
  CHECK(img.cols() == 32);
  CHECK((img == b.render(b.subject(3), GraspClass::two_edged, false, 4)).all());
  CHECK_FALSE((img == other.render(other.subject(3), GraspClass::two_edged, false, 4)).all());
  CHECK(img.minCoeff() >= 0.0);
  CHECK(img.maxCoeff() <= 255.0);
  CHECK((img == img.round()).all());
  // A hand covers part of the frame and leaves background around it.
  const double covered = (img > 20.0).cast<double>().mean();
  CHECK(covered > 0.2);
  CHECK(covered < 0.9);

  const auto set = a.dataset(2, 3);
  REQUIRE(set.size() == 2 * 4 * 3 * 2);
  CHECK(set[0].subject == 0);
  CHECK(set[0].label == GraspClass::planar);
  CHECK(set[0].right_hand);
  CHECK_FALSE(set[1].right_hand);
  CHECK(set.back().label == GraspClass::cylindrical);
  CHECK((set[5].image == a.render(a.subject(0), set[5].label, set[5].right_hand, set[5].grasp))
            .all());
}

TEST_CASE("Palm-grasp classes have their pressure signatures", "[sim][palm_grasp]") {
  // Noise-free, unrotated, centred grasps so the profiles along the fingers are clean.
  PalmGraspConfig cfg;
  cfg.mult_noise = 0.0;
  cfg.add_noise = 0.0;
  cfg.dead_tactel_prob = 0.0;
  cfg.offset_sd = 0.0;
  cfg.rotation_sd_deg = 0.0;
  cfg.object_angle_deg = 0.0;
  cfg.object_offset = 0.0;
  const PalmGraspSynth syn(cfg, 1);
  const auto s = syn.subject(0);
  const auto planar = syn.render(s, GraspClass::planar, true, 0);
  const auto one = syn.render(s, GraspClass::one_edged, true, 0);
  const auto two = syn.render(s, GraspClass::two_edged, true, 0);
  const auto cyl = syn.render(s, GraspClass::cylindrical, true, 0);
  // Gaps between fingers: in a finger row, columns that read well below the fingers on both
  // sides.
  const auto top = planar.row(6);
  int gaps = 0;
  for (Eigen::Index c = 2; c + 2 < top.size(); ++c) {
    gaps += top(c) < 0.7 * std::min(top(c - 2), top(c + 2)) && top(c) <= top(c - 1) &&
                    top(c) <= top(c + 1)
                ? 1
                : 0;
  }
  CHECK(gaps >= 2);
  // Edged classes have a sharp ridge: inside the hand (rows where the neighbours two rows away
  // both carry pressure), a row of the profile stands far above the mean of those neighbours;
  // the cylinder's profile is smooth.
  const auto ridge = [](const taxel::image::ImageD& img) {
    const Eigen::VectorXd p = row_profile(img);
    double best = 0.0;
    for (Eigen::Index r = 2; r + 2 < p.size(); ++r) {
      if (std::min(p(r - 2), p(r + 2)) < 0.3 * p.maxCoeff()) continue;
      best = std::max(best, p(r) - 0.5 * (p(r - 2) + p(r + 2)));
    }
    return best / p.maxCoeff();
  };
  const auto ridge_rows = [](const taxel::image::ImageD& img) {
    const Eigen::VectorXd p = row_profile(img);
    int peaks = 0;
    for (Eigen::Index r = 1; r + 1 < p.size(); ++r)
      peaks += p(r) > p(r - 1) && p(r) > p(r + 1) && p(r) > 0.6 * p.maxCoeff() ? 1 : 0;
    return peaks;
  };
  CHECK(ridge_rows(two) >= 2);
  CHECK(ridge_rows(one) >= 1);
  // The cylinder lies across the palm (its axis near row 0.45 * 32 + 0.45 * palm_length = 20)
  // and its pressure falls away from the axis: the fingertips read much less than the axis
  // row, unlike the planar grasp.
  INFO("cylinder rows 20, 5: " << cyl.row(20).mean() << ", " << cyl.row(5).mean());
  INFO("planar rows 20, 5: " << planar.row(20).mean() << ", " << planar.row(5).mean());
  CHECK(cyl.row(20).mean() > 2.0 * cyl.row(5).mean());
  CHECK(planar.row(5).mean() > 0.5 * planar.row(20).mean());
  INFO("ridge one, two, cylinder, planar: " << ridge(one) << ", " << ridge(two) << ", "
                                            << ridge(cyl) << ", " << ridge(planar));
  CHECK(ridge(one) > 2.0 * ridge(cyl));
  CHECK(ridge(two) > 2.0 * ridge(cyl));
  CHECK(ridge(one) > 1.8 * ridge(planar));
  // The left hand's outline is the mirror image of the right's (pressures differ: each grasp
  // draws its own force and object placement).
  const auto left = syn.render(s, GraspClass::planar, false, 0);
  CHECK(((left.rowwise().reverse() > 0.0) == (planar > 0.0)).all());
}

TEST_CASE("Palm-grasp configuration errors name the field", "[sim][palm_grasp]") {
  PalmGraspConfig bad;
  bad.fingers = 7;
  CHECK_THROWS_WITH(PalmGraspSynth(bad), Catch::Matchers::Contains("fingers = 7"));
  PalmGraspConfig tiny;
  tiny.rows = 2;
  CHECK_THROWS_AS(PalmGraspSynth(tiny), std::invalid_argument);
  PalmGraspConfig range;
  range.cylinder_radius = {5.0, 1.0};
  CHECK_THROWS_AS(PalmGraspSynth(range), std::invalid_argument);
}
