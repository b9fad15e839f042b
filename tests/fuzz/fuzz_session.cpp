// SPDX-License-Identifier: MIT
// Fuzzes the session path as taxel-fuse --session takes it: a recorded DSACON32m session (the
// input up to a line "#poses") replayed through DsaconDevice, with the drivers' pad poses CSV
// (the rest of the input) keyed by the controller's clock. Each step may only throw the errors
// it documents (a malformed file or poses file, a protocol or transport failure, a pose that is
// not rigid); every contact it makes must be finite.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>
#include <taxel/drivers/convert.hpp>
#include <taxel/drivers/session.hpp>
#include <vector>

namespace td = taxel::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t cut = input.find("\n#poses\n");
  const std::string_view session = input.substr(0, cut);
  const std::string_view poses =
      cut == std::string_view::npos ? std::string_view() : input.substr(cut + 8);
  td::SessionPrefix file = td::parse_session_prefix(session, "<session>");
  if (file.chunks.empty()) return 0;
  // A replay answers at once or never: a millisecond is enough to wait.
  td::DsaconDevice dev(td::ReplayTransport(std::move(file.chunks)),
                       {.reply_timeout = td::Timeout(1), .frame_timeout = td::Timeout(1)});
  try {
    dev.open();
    dev.start();
    td::SessionPoses table;
    if (!poses.empty()) table = td::SessionPoses(poses, "<poses>", dev.matrices().size());
    const std::vector<Eigen::Isometry3d> fixed = td::static_matrix_poses(dev.matrices());
    std::vector<Eigen::Isometry3d> at;
    std::vector<taxel::Contact<double>> out;
    for (int frames = 0; frames < 64; ++frames) {
      const auto f = dev.read_frame();
      if (!f) break;
      (void)table.frame_poses(*f, fixed, 8, "<poses>", at);
      try {
        td::frame_contacts(*f, dev.matrices(), at, out);
      } catch (const std::invalid_argument&) {  // a matrix the sensor model refuses
      }
    }
    for (const auto& c : out) {
      if (!c.position.allFinite() || !c.covariance.allFinite()) std::abort();
    }
    (void)td::finish_replay(dev, file.error);
  } catch (const taxel::IoError&) {
  } catch (const td::TransportError&) {
  } catch (const td::dsa::ProtocolError&) {
  } catch (const taxel::ProtocolError&) {
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
