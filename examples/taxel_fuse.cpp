// SPDX-License-Identifier: MIT
// taxel-fuse: a contact stream (CSV) in, the fused cloud (PLY) out, with the fusion policy and
// the spatial index chosen by option.
#include <chrono>
#include <cstdio>
#include <exception>
#include <limits>
#include <map>
#include <string>
#include <string_view>
#include <taxel/fusion.hpp>
#include <taxel/index.hpp>
#include <taxel/io/contacts_csv.hpp>
#include <taxel/io/ply.hpp>
#include <vector>

#include "cli.hpp"

namespace {

constexpr const char* kUsage = R"usage(usage: taxel-fuse [options] CONTACTS.csv CLOUD.ply

Fuses a contact stream into a compact cloud: each contact joins the nearest fused point within
the association radius, or starts a new one. CONTACTS.csv has a header naming its columns
(time, x, y, z, cxx, cxy, cxz, cyy, cyz, czz, nx, ny, nz, pressure; x, y, z required; see
include/taxel/io/contacts_csv.hpp); CLOUD.ply gets the fused points with the fields
"observations", "covariance_trace" and "last_time". Units: metres and seconds.

options:
  --policy surfel|kalman|average|raw    fusion policy (default surfel: a Kalman point that
                    fits its patch's curvature from the contact normals and removes the
                    chord sag; kalman: the plain per-point Kalman filter; average: running
                    mean; raw: every contact kept)
  --index voxel-hash|kd-tree|brute-force   spatial index (default voxel-hash)
  --radius R        association radius [m] (default 0.0034, one DSA tactel pitch)
  --gate CHI2       surfel, kalman: Mahalanobis gate (e.g. 11.345 for 99 %; default none)
  --process-noise Q surfel, kalman: process noise [m] per update (default 0)
  --ascii           write ASCII PLY (default binary little-endian)
  -h, --help        show this help

Prints the counts (contacts, added, fused, rejected by reason) and the time per contact.
Exit status: 0 on success, 1 for unreadable input, 2 for bad options.
)usage";

struct Options {
  std::string policy = "surfel";
  std::string index = "voxel-hash";
  double radius = 3.4e-3;
  double gate = 0.0;
  double process_noise = 0.0;
  bool ascii = false;
  std::vector<std::string> files;
};

template <class Cloud>
int fuse(const Options& o, typename Cloud::Config cfg,
         const std::vector<taxel::Contact<double>>& contacts, const taxel_cli::Args& args) {
  cfg.association_radius = o.radius;
  Cloud cloud(cfg);
  cloud.reserve(contacts.size());
  std::map<std::string, std::size_t> rejected;
  std::size_t added = 0, fused = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (const auto& c : contacts) {
    const auto r = cloud.insert(c);
    switch (r.status) {
      case taxel::fusion::InsertStatus::added:
        ++added;
        break;
      case taxel::fusion::InsertStatus::fused:
        ++fused;
        break;
      default:
        ++rejected[std::string(taxel::to_string(r.defect))];
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("contacts %zu\nadded %zu\nfused %zu\n", contacts.size(), added, fused);
  std::size_t total_rejected = 0;
  for (const auto& [why, n] : rejected) total_rejected += n;
  std::printf("rejected %zu", total_rejected);
  for (const auto& [why, n] : rejected) std::printf(" (%s %zu)", why.c_str(), n);
  std::printf("\npoints %zu\ntime %.0f ns per contact\n", cloud.size(),
              contacts.empty() ? 0.0 : 1e9 * s / static_cast<double>(contacts.size()));
  try {
    taxel::io::write_ply(
        o.files[1], cloud.to_point_cloud(),
        o.ascii ? taxel::io::PlyFormat::ascii : taxel::io::PlyFormat::binary_little_endian);
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  return 0;
}

template <class Policy>
int with_index(const Options& o, typename Policy::Config pc,
               const std::vector<taxel::Contact<double>>& contacts, const taxel_cli::Args& args) {
  namespace tf = taxel::fusion;
  namespace ti = taxel::index;
  if (o.index == "kd-tree") {
    typename tf::ContactCloud<Policy, ti::DynamicKdTree<double>>::Config cfg;
    cfg.fusion = pc;
    return fuse<tf::ContactCloud<Policy, ti::DynamicKdTree<double>>>(o, cfg, contacts, args);
  }
  if (o.index == "brute-force") {
    typename tf::ContactCloud<Policy, ti::BruteForce<double>>::Config cfg;
    cfg.fusion = pc;
    return fuse<tf::ContactCloud<Policy, ti::BruteForce<double>>>(o, cfg, contacts, args);
  }
  typename tf::ContactCloud<Policy, ti::VoxelHash<double>>::Config cfg;
  cfg.fusion = pc;
  return fuse<tf::ContactCloud<Policy, ti::VoxelHash<double>>>(o, cfg, contacts, args);
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::Args args("taxel-fuse", argc, argv);
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--policy") {
      o.policy = std::string(args.value());
      if (o.policy != "surfel" && o.policy != "kalman" && o.policy != "average" &&
          o.policy != "raw") {
        args.fail("--policy must be surfel, kalman, average or raw");
      }
    } else if (a == "--index") {
      o.index = std::string(args.value());
      if (o.index != "voxel-hash" && o.index != "kd-tree" && o.index != "brute-force") {
        args.fail("--index must be voxel-hash, kd-tree or brute-force");
      }
    } else if (a == "--radius") {
      o.radius = args.number<double>(-kInf, kInf);
    } else if (a == "--gate") {
      o.gate = args.number<double>(-kInf, kInf);
    } else if (a == "--process-noise") {
      o.process_noise = args.number<double>(-kInf, kInf);
    } else if (a == "--ascii") {
      o.ascii = true;
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else {
      o.files.emplace_back(a);
    }
  }
  if (o.files.size() != 2) args.fail("expected CONTACTS.csv and CLOUD.ply (see --help)");
  std::vector<taxel::Contact<double>> contacts;
  try {
    contacts = taxel::io::read_contacts_csv(o.files[0]);
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  namespace tf = taxel::fusion;
  try {
    if (o.policy == "raw") return with_index<tf::Raw<double>>(o, {}, contacts, args);
    if (o.policy == "average") return with_index<tf::Average<double>>(o, {}, contacts, args);
    tf::Kalman<double>::Config kc;
    kc.process_noise = o.process_noise;
    if (o.gate != 0.0) kc.gate_chi2 = o.gate;
    if (o.policy == "kalman") return with_index<tf::Kalman<double>>(o, kc, contacts, args);
    return with_index<tf::Surfel<double>>(o, {.kalman = kc}, contacts, args);
  } catch (const std::invalid_argument& e) {  // a configuration the cloud refuses
    args.fail(e.what());
  }
}
