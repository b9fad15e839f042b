// SPDX-License-Identifier: MIT
// 03: a pad slides over a box; the contacts are fused with Kalman filters into a compact cloud,
// which is then aligned to the box's model by ICP from a start 10 deg / 5 mm off, with
// point-to-point, point-to-plane and a robust kernel. Prints iterations, time, RMSE and pose
// error; writes the model and the cloud before and after alignment as PLY.
//   ./03_icp_align [--quick] [--out DIR]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <string>
#include <string_view>
#include <taxel/taxel.hpp>

#include "cli.hpp"

namespace {

using namespace taxel;
namespace tr = taxel::registration;

// RMS over the cloud of |T_est p - T_true p|: the pose error as the points feel it.
double pose_error(const std::vector<Vec3d>& pts, const Isometry3d& est, const Isometry3d& truth) {
  double sum = 0.0;
  for (const auto& p : pts) sum += (est * p - truth * p).squaredNorm();
  return std::sqrt(sum / static_cast<double>(pts.size()));
}

template <class Error, class Kernel = tr::NoKernel>
void align(const char* name, const tr::Target<double>& model, const PointCloud<double>& cloud,
           const Isometry3d& start, const Isometry3d& truth, Kernel kernel = {}) {
  tr::IcpConfig cfg;
  cfg.max_iterations = 100;
  cfg.max_distance = 0.01;
  tr::Icp<Error, Kernel> icp(cfg, kernel);
  const auto t0 = std::chrono::steady_clock::now();
  const tr::IcpResult r = icp.align(model, cloud, start);
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const Isometry3d err = r.transform * truth.inverse();
  std::printf(
      "  %-28s %-13s %4d it %7.2f ms  rmse %5.3f mm  pose error %6.3f mm (%5.3f deg, %5.3f mm)\n",
      name, std::string(to_string(r.status)).c_str(), r.iterations, ms, 1e3 * r.rmse,
      1e3 * pose_error(cloud.points, r.transform, truth),
      Eigen::AngleAxisd(err.linear()).angle() * 180.0 / std::numbers::pi,
      1e3 * err.translation().norm());
}

constexpr const char* kUsage =
    "usage: 03_icp_align [--quick] [--out DIR]\n"
    "Fuses a simulated sliding exploration of a box with Kalman filters and aligns the cloud\n"
    "to the box model by ICP (point-to-point, point-to-plane, Huber).\n";

}  // namespace

int main(int argc, char** argv) try {
  taxel_cli::check_stdout_at_exit("03_icp_align");
  const taxel_cli::StudyOptions opt =
      taxel_cli::parse_study_options("03_icp_align", kUsage, "icp-align", argc, argv);
  const bool quick = opt.quick;
  const std::filesystem::path out = opt.out;
  std::filesystem::create_directories(out);
  const sim::Box box(Vec3d(0.04, 0.03, 0.02));

  // The exploration: several slides from random starts, 0.5 mm noise along the pad normal.
  std::vector<Contact<double>> contacts;
  const int slides = quick ? 5 : 6;
  for (int s = 0; s < slides; ++s) {
    const auto part = sim::sliding_exploration(box, quick ? 3000 : 8000,
                                               {.speed = 0.08,
                                                .sigma_normal = 0.5e-3,
                                                .sigma_tilt = 0.1,
                                                .seed = 11 + static_cast<std::uint64_t>(s)});
    contacts.insert(contacts.end(), part.begin(), part.end());
  }
  fusion::ContactCloud<fusion::Kalman<double>, index::VoxelHash<double>> fused(
      {.association_radius = 3.4e-3});
  (void)fused.insert(std::span(contacts));
  const PointCloud<double> world = fused.to_point_cloud();
  const auto surface = sim::surface_error(box, world.points);
  std::printf("exploration: %zu contacts fused into %zu points (rms %.3f mm from the surface)\n",
              contacts.size(), world.size(), 1e3 * surface.rms);

  // The cloud as the hand sees it: in its own frame, at an unknown pose.
  Isometry3d truth = Isometry3d::Identity();  // T_model_hand
  truth.linear() = Eigen::AngleAxisd(0.8, Vec3d(1, -2, 0.5).normalized()).toRotationMatrix();
  truth.translation() = Vec3d(0.12, -0.05, 0.3);
  const PointCloud<double> cloud = transformed(world, truth.inverse());
  Isometry3d offset = Isometry3d::Identity();
  offset.linear() = Eigen::AngleAxisd(10.0 * std::numbers::pi / 180.0, Vec3d(0, 1, 1).normalized())
                        .toRotationMatrix();
  offset.translation() = Vec3d(0.003, -0.004, 0.0);
  const Isometry3d start = offset * truth;

  const tr::Target<double> model(sim::sample_surface(box, quick ? 5000 : 10000, 1));
  std::printf("model: %zu points; start %.1f deg / %.1f mm from the truth\n", model.size(), 10.0,
              5.0);
  align<tr::PointToPoint>("point-to-point", model, cloud, start, truth);
  align<tr::PointToPlane>("point-to-plane", model, cloud, start, truth);
  align<tr::PointToPlane, tr::Huber>("point-to-plane, Huber 1 mm", model, cloud, start, truth,
                                     tr::Huber{1e-3});

  tr::Icp<tr::PointToPlane> icp(tr::IcpConfig{.max_iterations = 100, .max_distance = 0.01});
  const tr::IcpResult best = icp.align(model, cloud, start);
  io::write_ply((out / "model.ply").string(), sim::sample_surface(box, 10000, 1));
  io::write_ply((out / "cloud_start.ply").string(), transformed(cloud, start));
  io::write_ply((out / "cloud_aligned.ply").string(), transformed(cloud, best.transform));
  io::write_ply((out / "cloud_sensor_frame.ply").string(), cloud);
  std::printf("wrote %s/{model,cloud_start,cloud_aligned,cloud_sensor_frame}.ply\n", out.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "03_icp_align: %s\n", e.what());
  return 1;
}
