// SPDX-License-Identifier: MIT
// 07: a DSACON32m stream, live or replayed, into contact fusion. Each frame's matrices become
// contacts at the pads' poses (from a poses file, or the controller's static matrix poses) and
// go into a ContactCloud<Kalman, VoxelHash>. Prints the stream and fusion rates and writes the
// fused cloud as PLY.
//   ./07_stream_fusion [--replay SESSION.txt [--poses POSES.csv]] [--serial DEV | --usb VID:PID]
//                      [--frames N] [--per-pad] [--realtime] [--out DIR]
// Without a source it replays the session committed in data/sessions (a simulated grasp of a
// cylinder recorded through the emulated controller by taxel-record).
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <taxel/drivers/convert.hpp>
#include <taxel/drivers/dsacon_device.hpp>
#include <taxel/drivers/serial.hpp>
#include <taxel/drivers/session.hpp>
#include <taxel/drivers/usb.hpp>
#include <taxel/fusion.hpp>
#include <taxel/index.hpp>
#include <taxel/io/ply.hpp>
#include <type_traits>

#include "../../examples/cli.hpp"
#include "device_cli.hpp"

namespace {

namespace td = taxel::drivers;
namespace cli = taxel_drivers_cli;

constexpr const char* kUsage = R"usage(usage: 07_stream_fusion [options]

Streams a DSACON32m (live, or a recorded session) into Kalman contact fusion and prints the
rates. Without a source: the session in data/sessions/ (a simulated cylinder grasp).

  --replay FILE      a recorded session (taxel-record)
  --poses FILE.csv   pad poses per frame; default: the controller's static matrix poses
  --serial DEVICE    a live controller on a serial port (115200 baud)
  --usb VID:PID      a live controller on USB bulk endpoints (hex ids)
  --frames N         stop after N frames (default: all of a session, 300 live)
  --per-pad          one contact per matrix and frame instead of one per tactel
  --realtime         replay at the recorded pace
  --out DIR          where cloud.ply goes (default stream-fusion)
  -h, --help         show this help
)usage";

struct Options {
  std::string replay, poses, serial, usb, out = "stream-fusion";
  long frames = -1;
  bool per_pad = false, realtime = false;
};

// `file_error`: the malformed line that cut a replayed session short ("" for a whole file or a
// live device).
template <class T>
int run(T transport, const Options& o, const std::string& poses_text, const taxel_cli::Args& args,
        const std::string& file_error = {}) {
  const td::Timeout timeout(o.replay.empty() ? 1000 : 50);  // a replay answers at once or never
  td::DsaconDevice dev(std::move(transport), {.reply_timeout = timeout, .frame_timeout = timeout});
  taxel::fusion::ContactCloud<taxel::fusion::Kalman<double>, taxel::index::VoxelHash<double>> cloud(
      {.association_radius = 4e-3});
  std::vector<taxel::Contact<double>> contacts;
  std::size_t total_contacts = 0, frames = 0, posed = 0;
  double fuse_seconds = 0.0;
  const long limit = o.frames >= 0 ? o.frames : o.replay.empty() ? 300 : -1;  // live: 300
  const auto t0 = std::chrono::steady_clock::now();
  std::string shortfall;  // why a replay stopped before the end of its recording
  try {
    dev.open();
    const cli::Poses fixed = cli::static_poses(dev.matrices());
    td::SessionPoses table;
    if (!o.poses.empty()) table = td::SessionPoses(poses_text, o.poses, dev.matrices().size());
    cli::Poses poses;
    dev.start();
    while (limit < 0 || long(frames) < limit) {
      const auto f = dev.read_frame();
      if (!f) {  // the end of the session, or a silent device
        if constexpr (std::is_same_v<T, td::ReplayTransport>) {
          shortfall = td::finish_replay(dev, file_error);
        }
        break;
      }
      ++frames;
      posed += table.frame_poses(*f, fixed, td::PadCalibration{}.threshold, o.poses, poses);
      contacts.clear();
      td::frame_contacts(
          *f, dev.matrices(), poses, contacts,
          o.per_pad ? taxel::sim::ContactMode::per_pad : taxel::sim::ContactMode::per_tactel);
      const auto a = std::chrono::steady_clock::now();
      cloud.insert(std::span<const taxel::Contact<double>>(contacts));
      fuse_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count();
      total_contacts += contacts.size();
    }
    dev.close();
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const auto s = dev.stats();
  std::printf("matrices %zu, tactels %zu\n", dev.matrices().size(), dev.cells());
  std::printf("frames %zu (dropped %llu, bad %llu, with poses %zu)\n", frames,
              static_cast<unsigned long long>(s.dropped_frames),
              static_cast<unsigned long long>(s.bad_frames), posed);
  std::printf("contacts %zu -> fused points %zu (compaction %.1fx)\n", total_contacts, cloud.size(),
              cloud.empty() ? 0.0 : double(total_contacts) / double(cloud.size()));
  std::printf("stream %.1f frames/s over %.2f s; fusion %.0f ns per contact\n",
              wall > 0 ? double(frames) / wall : 0.0, wall,
              total_contacts ? 1e9 * fuse_seconds / double(total_contacts) : 0.0);
  std::filesystem::create_directories(o.out);
  const std::string ply = (std::filesystem::path(o.out) / "cloud.ply").string();
  try {
    taxel::io::write_ply(ply, cloud.to_point_cloud());
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  std::printf("wrote %s\n", ply.c_str());
  if (!shortfall.empty()) {
    args.fail(o.replay + ": " + shortfall + "; the cloud holds the frames before it", 1);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("07_stream_fusion");
  taxel_cli::Args args("07_stream_fusion", argc, argv);
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--replay") {
      o.replay = std::string(args.value());
    } else if (a == "--poses") {
      o.poses = std::string(args.value());
    } else if (a == "--serial") {
      o.serial = std::string(args.value());
    } else if (a == "--usb") {
      o.usb = std::string(args.value());
    } else if (a == "--frames") {
      o.frames = args.number<long>(1, 100000000);
    } else if (a == "--per-pad") {
      o.per_pad = true;
    } else if (a == "--realtime") {
      o.realtime = true;
    } else if (a == "--out") {
      o.out = std::string(args.value());
    } else {
      args.fail("unknown argument '" + std::string(a) + "' (see --help)");
    }
  }
  if (int(!o.replay.empty()) + int(!o.serial.empty()) + int(!o.usb.empty()) > 1)
    args.fail("give at most one of --replay, --serial, --usb");
  if (o.replay.empty() && o.serial.empty() && o.usb.empty()) {
    o.replay = TAXEL_SESSION_DIR "/cylinder_grasp.session";
    if (o.poses.empty()) o.poses = TAXEL_SESSION_DIR "/cylinder_grasp_poses.csv";
  }
  try {
    const std::string poses_text = o.poses.empty() ? std::string() : taxel::io::read_file(o.poses);
    if (!o.replay.empty()) {
      td::SessionPrefix file = td::read_session_prefix(o.replay);
      if (file.chunks.empty() && !file.error.empty()) throw td::SessionError(file.error);
      return run(td::ReplayTransport(std::move(file.chunks), o.realtime), o, poses_text, args,
                 file.error);
    }
    if (!o.serial.empty()) return run(td::SerialTransport(o.serial), o, poses_text, args);
    const auto ids = cli::parse_pair(o.usb, 16);
    if (!ids) args.fail("--usb: '" + o.usb + "' is not of the form VID:PID (hex)");
    return run(td::UsbTransport({.vendor_id = std::uint16_t(ids->first),
                                 .product_id = std::uint16_t(ids->second)}),
               o, poses_text, args);
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
}
