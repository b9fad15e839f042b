// SPDX-License-Identifier: MIT
// Consumer of the installed taxel::drivers: a command encoded, parsed back, a loopback link.
#include <taxel/drivers/dsa_protocol.hpp>
#include <taxel/drivers/transport.hpp>
#include <taxel/drivers/usb.hpp>

int main() {
  namespace dsa = taxel::drivers::dsa;
  dsa::Parser p;
  p.feed(dsa::encode_query_matrix_info(3));
  const auto packet = p.next();
  auto [a, b] = taxel::drivers::LoopbackTransport::pair();
  a.open();
  b.open();
  const std::uint8_t byte[1] = {42};
  a.write(byte);
  std::uint8_t got[1] = {0};
  const bool ok = packet && packet->payload.size() == 1 && packet->payload[0] == 3 &&
                  b.read(got, taxel::drivers::Timeout(100)) == 1 && got[0] == 42;
  return ok ? 0 : 1;
}
