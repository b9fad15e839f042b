// SPDX-License-Identifier: MIT
// taxel-record: records a DSACON32m session (every byte both ways, time-stamped) from a serial
// port, a USB device, or the emulated controller fed by a simulated grasp.
#include <atomic>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>
#include <string_view>
#include <taxel/drivers/dsacon_device.hpp>
#include <taxel/drivers/dsacon_emulator.hpp>
#include <taxel/drivers/serial.hpp>
#include <taxel/drivers/session.hpp>
#include <taxel/drivers/usb.hpp>
#include <thread>

#include "../../examples/cli.hpp"
#include "../../examples/report.hpp"
#include "device_cli.hpp"

namespace {

namespace td = taxel::drivers;
namespace cli = taxel_drivers_cli;

constexpr const char* kUsage = R"usage(usage: taxel-record [options] SESSION.txt

Opens a DSACON32m tactile controller, streams frames and records the whole conversation (every
byte both ways, time-stamped) to SESSION.txt, which ReplayTransport and 07_stream_fusion play
back without hardware. SESSION.txt may be `-` (standard output; the summary then goes to
standard error).

source (one):
  --serial DEVICE    a serial port, e.g. /dev/ttyUSB0 (115200 baud unless --baud)
  --usb VID:PID      a USB device with bulk IN/OUT endpoints (hex ids, e.g. 1234:5678)
  --usb-bus BUS:ADDR the same, by bus number and device address (decimal)
  --emulate SHAPE    the software controller, streaming a simulated three-finger hand grasping
                     sphere, cylinder or box (no hardware)
options:
  --frames N         frames to record (default 100; with --emulate, every simulated frame)
  --baud B           serial baud rate (default 115200)
  --timeout MS       reply and frame timeout (default 1000)
  --poses FILE.csv   with --emulate: write the pads' poses per frame (for 07_stream_fusion)
  --grasps G         with --emulate: grasps to simulate (default 8)
  --period-ms P      with --emulate: frame period (default 33.3, about 30 frames/s)
  --seed S           with --emulate (default 1)
  --format text|json|csv  how the summary is printed (default text)
  -h, --help         show this help
  --version          show taxel's version

Exit status: 0 on success, 1 when the device fails or a file cannot be written, 2 for bad
options.
)usage";

struct Options {
  std::string serial, usb, usb_bus, emulate, poses, out;
  unsigned baud = 115200;
  int frames = -1, grasps = 8;  // frames: 100 from a device, every simulated one emulated
  double period_ms = 1000.0 / 30.0;
  long timeout_ms = 1000;
  std::uint64_t seed = 1;
  taxel_cli::Format format = taxel_cli::Format::text;
};

// The summary, printed once at the end.
taxel_cli::Json summary = taxel_cli::Json::object();

template <class T>
int record(T transport, const Options& o, const taxel_cli::Args& args,
           const std::string& poses_text = {}) {
  td::DsaconDevice dev(
      td::RecordingTransport<T>(std::move(transport)),
      {.reply_timeout = td::Timeout(o.timeout_ms), .frame_timeout = td::Timeout(o.timeout_ms)});
  int got = 0;
  try {
    dev.open();
    dev.start();
    for (; got < o.frames; ++got) {
      if (!dev.read_frame()) {
        args.fail("no frame within " + std::to_string(o.timeout_ms) + " ms after " +
                      std::to_string(got) + " frames",
                  1);
      }
    }
    dev.stop();
    dev.close();
    // The session and its poses as a set: neither replaces an earlier run's file alone.
    std::vector<std::pair<std::string, std::string>> outputs{
        {o.out, td::format_session(dev.transport().chunks())}};
    if (!o.poses.empty()) outputs.emplace_back(o.poses, poses_text);
    taxel_cli::write_outputs(outputs);
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
  const auto s = dev.stats();
  std::size_t bytes = 0;
  for (const auto& c : dev.transport().chunks()) bytes += c.bytes.size();
  summary["controller_sw"] = unsigned(dev.controller_info().sw_version);
  summary["controller_serial"] = unsigned(dev.controller_info().serial_no);
  summary["matrices"] = dev.matrices().size();
  summary["tactels"] = dev.cells();
  summary["frames"] = got;
  summary["dropped"] = s.dropped_frames;
  summary["crc_errors"] = s.link.crc_errors;
  summary["bytes"] = bytes;
  summary["session"] = o.out == "-" ? std::string("<stdout>") : o.out;
  return 0;
}

template <class Shape>
int emulate(const Shape& shape, const Options& o, const taxel_cli::Args& args) {
  const cli::SimulatedHand hand = cli::simulate_hand(shape, o.grasps, o.period_ms, o.seed);
  Options with_frames = o;
  if (with_frames.frames < 0) with_frames.frames = static_cast<int>(hand.frames.size());
  td::EmulatorConfig cfg;
  cfg.matrices = hand.matrices;
  cfg.period_ms = o.period_ms;
  const std::size_t cells = hand.frames.empty() ? 0 : hand.frames[0].size();
  td::DsaconEmulator emulator(cfg, [&](std::uint64_t i) {
    return i < hand.frames.size() ? hand.frames[i] : std::vector<std::uint16_t>(cells, 0);
  });
  // Not a structured binding: the lambda below uses `device`, which clang before 16 refuses.
  std::pair<td::LoopbackTransport, td::LoopbackTransport> link = td::LoopbackTransport::pair();
  td::LoopbackTransport& host = link.first;
  td::LoopbackTransport& device = link.second;
  device.open();
  std::atomic<bool> stop{false};
  std::thread controller([&] { emulator.serve(device, stop, true); });
  int rc = 1;
  try {
    rc = record(std::move(host), with_frames, args, cli::poses_csv(hand.poses));
  } catch (...) {
    stop = true;
    controller.join();
    throw;
  }
  stop = true;
  controller.join();
  if (!o.poses.empty()) summary["poses"] = o.poses;
  return rc;
}

}  // namespace

int main(int argc, char** argv) {
  taxel_cli::check_stdout_at_exit("taxel-record");
  taxel_cli::print_version_if_asked("taxel-record", argc, argv);
  taxel_cli::Args args("taxel-record", argc, argv);
  Options o;
  std::string_view a;
  while (args.next(a)) {
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "--serial") {
      o.serial = std::string(args.value());
    } else if (a == "--usb") {
      o.usb = std::string(args.value());
    } else if (a == "--usb-bus") {
      o.usb_bus = std::string(args.value());
    } else if (a == "--emulate") {
      o.emulate = std::string(args.value());
      if (o.emulate != "sphere" && o.emulate != "cylinder" && o.emulate != "box")
        args.fail("--emulate takes sphere, cylinder or box");
    } else if (a == "--frames") {
      o.frames = args.number<int>(1, 10000000);
    } else if (a == "--baud") {
      o.baud = args.number<unsigned>(1, 4000000);
    } else if (a == "--timeout") {
      o.timeout_ms = args.number<long>(1, 600000);
    } else if (a == "--poses") {
      o.poses = std::string(args.value());
    } else if (a == "--grasps") {
      o.grasps = args.number<int>(1, 10000);
    } else if (a == "--period-ms") {
      o.period_ms = args.number<double>(1.0, 10000.0);
    } else if (a == "--seed") {
      o.seed = args.number<std::uint64_t>(0, std::numeric_limits<std::uint64_t>::max());
    } else if (a == "--format") {
      o.format = taxel_cli::to_format(args.choice("text|json|csv"));
    } else if (a.size() > 1 && a[0] == '-') {
      args.fail("unknown option '" + std::string(a) + "' (see --help)");
    } else if (o.out.empty()) {
      o.out = std::string(a);
    } else {
      args.fail("expected one SESSION.txt (see --help)");
    }
  }
  if (o.out.empty()) args.fail("expected SESSION.txt (see --help)");
  const int sources = int(!o.serial.empty()) + int(!o.usb.empty()) + int(!o.usb_bus.empty()) +
                      int(!o.emulate.empty());
  if (sources != 1) args.fail("give exactly one of --serial, --usb, --usb-bus, --emulate");
  if (!o.poses.empty() && o.emulate.empty()) args.fail("--poses needs --emulate");
  args.check_output(o.out, {o.serial}, {o.poses});
  const auto pair = [&](const std::string& text, int base, const char* what) {
    const auto p = cli::parse_pair(text, base);
    if (!p) args.fail(std::string(what) + ": '" + text + "' is not of the form A:B");
    return *p;
  };
  if (o.frames < 0 && o.emulate.empty()) o.frames = 100;
  const auto done = [&](int rc) {
    const std::string text = taxel_cli::render(summary, o.format);
    std::fwrite(text.data(), 1, text.size(), o.out == "-" ? stderr : stdout);
    return rc;
  };
  try {
    if (!o.serial.empty()) return done(record(td::SerialTransport(o.serial, o.baud), o, args));
    if (!o.usb.empty()) {
      const auto [vid, pid] = pair(o.usb, 16, "--usb");
      return done(record(
          td::UsbTransport({.vendor_id = std::uint16_t(vid), .product_id = std::uint16_t(pid)}), o,
          args));
    }
    if (!o.usb_bus.empty()) {
      const auto [bus, addr] = pair(o.usb_bus, 10, "--usb-bus");
      if (bus > 255 || addr > 255) args.fail("--usb-bus: bus and address are at most 255");
      return done(record(
          td::UsbTransport({.bus = std::uint8_t(bus), .address = std::uint8_t(addr)}), o, args));
    }
    if (o.emulate == "sphere") return done(emulate(taxel::sim::Sphere(0.04), o, args));
    if (o.emulate == "cylinder") return done(emulate(taxel::sim::Cylinder(0.03, 0.05), o, args));
    return done(emulate(taxel::sim::Box(taxel::Vec3d(0.04, 0.03, 0.02)), o, args));
  } catch (const std::exception& e) {
    args.fail(e.what(), 1);
  }
}
