// SPDX-License-Identifier: MIT
// Fuzzes the DSACON32m codec: the incremental parser fed the input in pieces whose sizes the
// input chooses, every typed decoder on every packet it yields, frame decoding for cell counts
// from the input, and the session-file parser. Invariants: no crash, no undefined behaviour,
// errors only as dsa::ProtocolError / SessionError, and the parser never holds a complete
// packet it did not return.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <taxel/drivers/dsa_protocol.hpp>
#include <taxel/drivers/session.hpp>

namespace dsa = taxel::drivers::dsa;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const std::size_t cells = 1 + data[0] * 4;  // 1..1021 tactels
  const std::size_t step = 1 + data[1] % 64;  // bytes per feed
  const std::span<const std::uint8_t> bytes(data + 2, size - 2);
  dsa::Parser parser(2048);
  for (std::size_t at = 0; at < bytes.size(); at += step) {
    parser.feed(bytes.subspan(at, std::min(step, bytes.size() - at)));
    while (auto p = parser.next()) {
      if (p->payload.size() > 2048) __builtin_trap();
      try {
        switch (static_cast<dsa::PacketId>(p->id)) {
          case dsa::PacketId::frame: {
            const auto f = dsa::decode_frame(p->payload, cells);
            if (f.texels.size() != cells) __builtin_trap();
            break;
          }
          case dsa::PacketId::controller_info:
            (void)dsa::decode_controller_info(p->payload);
            break;
          case dsa::PacketId::sensor_info:
            (void)dsa::decode_sensor_info(p->payload);
            break;
          case dsa::PacketId::matrix_info:
            (void)dsa::decode_matrix_info(p->payload);
            break;
          default:
            (void)dsa::decode_error_code(p->payload);
            break;
        }
      } catch (const dsa::ProtocolError&) {
      }
      // Re-encoding a packet yields bytes the parser accepts as that packet.
      dsa::Parser again;
      again.feed(dsa::encode_packet(p->id, p->payload));
      const auto q = again.next();
      if (p->id != 0xAA && (!q || q->payload != p->payload)) __builtin_trap();
    }
  }
  try {
    (void)taxel::drivers::parse_session(
        std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  } catch (const taxel::drivers::SessionError&) {
  }
  return 0;
}
