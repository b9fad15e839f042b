// SPDX-License-Identifier: MIT
// Tests of the DSACON32m codec, the device over a loopback link with the emulated controller,
// recorded sessions, and the serial transport against a pseudo-terminal. No hardware needed.
#include <pty.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <random>
#include <taxel/drivers/convert.hpp>
#include <taxel/drivers/dsa_protocol.hpp>
#include <taxel/drivers/dsacon_device.hpp>
#include <taxel/drivers/dsacon_emulator.hpp>
#include <taxel/drivers/serial.hpp>
#include <taxel/drivers/session.hpp>
#include <taxel/fusion.hpp>
#include <thread>

namespace td = taxel::drivers;
namespace dsa = taxel::drivers::dsa;
using Bytes = std::vector<std::uint8_t>;

namespace {

Bytes hex(std::string_view s) {
  Bytes out;
  for (std::size_t i = 0; i + 1 < s.size(); i += 2)
    out.push_back(static_cast<std::uint8_t>(std::stoi(std::string(s.substr(i, 2)), nullptr, 16)));
  return out;
}

// The CRC as the controller defines it, bit by bit: the MSB-first CCITT remainder of the byte
// (polynomial 0x1021) looked up LSB-first. An oracle independent of the table.
std::uint16_t crc_bitwise(const Bytes& bytes) {
  std::uint16_t crc = 0xFFFF;
  for (const std::uint8_t b : bytes) {
    unsigned r = ((crc ^ b) & 0xFFu) << 8;
    for (int k = 0; k < 8; ++k) r = (r & 0x8000u) ? (r << 1) ^ 0x1021u : r << 1;
    crc = static_cast<std::uint16_t>((crc >> 8) ^ (r & 0xFFFFu));
  }
  return crc;
}

std::vector<dsa::Packet> parse_all(dsa::Parser& p) {
  std::vector<dsa::Packet> out;
  while (auto q = p.next()) out.push_back(std::move(*q));
  return out;
}

// An emulated controller serving on one end of a loopback link, on its own thread.
struct Rig {
  explicit Rig(td::EmulatorConfig cfg = {}, td::DsaconEmulator::FrameSource src = {})
      : emulator(std::move(cfg), std::move(src)) {
    auto [host_end, device_end] = td::LoopbackTransport::pair();
    host = std::move(host_end);
    device = std::move(device_end);
    device->open();
    thread = std::thread([this] { emulator.serve(*device, stop, true); });
  }
  ~Rig() {
    stop = true;
    thread.join();
  }
  td::DsaconEmulator emulator;
  std::optional<td::LoopbackTransport> host, device;
  std::atomic<bool> stop{false};
  std::thread thread;
};

td::EmulatorConfig fast(std::vector<dsa::MatrixInfo> m = td::sdh2_matrices()) {
  td::EmulatorConfig c;
  c.matrices = std::move(m);
  c.period_ms = 2.0;
  return c;
}

std::vector<std::uint16_t> ramp(std::uint64_t index, std::size_t cells) {
  std::vector<std::uint16_t> v(cells);
  for (std::size_t i = 0; i < cells; ++i) v[i] = static_cast<std::uint16_t>((i * 7 + index) % 4096);
  return v;
}

}  // namespace

TEST_CASE("DSACON32m CRC: the published table and a bitwise oracle", "[drivers][codec]") {
  // Entries from SDHLibrary's crc.cpp.
  CHECK(dsa::kCrcTable[1] == 0x1021);
  CHECK(dsa::kCrcTable[8] == 0x8108);
  CHECK(dsa::kCrcTable[16] == 0x1231);
  CHECK(dsa::kCrcTable[255] == 0x1ef0);
  std::mt19937 rng(5);
  for (int n = 0; n < 200; ++n) {
    Bytes b(static_cast<std::size_t>(n));
    for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    REQUIRE(dsa::crc16(b) == crc_bitwise(b));
  }
}

TEST_CASE("DSACON32m codec: golden command bytes", "[drivers][codec]") {
  // Queries without payload carry no CRC.
  CHECK(dsa::encode_query_controller_info() == hex("aaaaaa010000"));
  CHECK(dsa::encode_query_sensor_info() == hex("aaaaaa020000"));
  // With payload: id, size and payload under the CRC, little-endian.
  const Bytes m = dsa::encode_query_matrix_info(2);
  REQUIRE(m.size() == 9);
  CHECK(Bytes(m.begin(), m.begin() + 7) == hex("aaaaaa0b010002"));
  const std::uint16_t crc = crc_bitwise(hex("0b010002"));
  CHECK(m[7] == (crc & 0xFF));
  CHECK(m[8] == (crc >> 8));
  const Bytes start = dsa::encode_set_acquisition(0, true, true);
  CHECK(Bytes(start.begin(), start.begin() + 9) == hex("aaaaaa030300810000"));
  const Bytes stop = dsa::encode_set_acquisition(0, false, false);
  CHECK(Bytes(stop.begin(), stop.begin() + 9) == hex("aaaaaa030300000000"));
}

TEST_CASE("DSACON32m codec: replies round-trip field by field", "[drivers][codec]") {
  dsa::ControllerInfo c{0, 0x01020304, 5, 0x0120, 6, 7, 8, 9, 1000000, 0x2A};
  const Bytes cb = dsa::encode_controller_info(c);
  CHECK(cb.size() == 18);  // as the controller sends it
  const dsa::ControllerInfo c2 = dsa::decode_controller_info(cb);
  CHECK(c2.serial_no == 0x01020304);
  CHECK(c2.sw_version == 0x0120);
  CHECK(c2.can_baudrate == 1000000);
  CHECK(c2.can_id == 0x2A);
  Bytes c19 = cb;
  c19.push_back(0x01);  // the 19-byte record: high byte of can_id
  CHECK(dsa::decode_controller_info(c19).can_id == 0x012A);
  const auto m = td::sdh2_matrices()[3];
  const Bytes mb = dsa::encode_matrix_info(m);
  CHECK(mb.size() == 52);
  const dsa::MatrixInfo m2 = dsa::decode_matrix_info(mb);
  CHECK(m2.cells_x == 6);
  CHECK(m2.cells_y == 13);
  CHECK(m2.texel_width == 3.4f);
  CHECK(m2.center[2] == m.center[2]);
  CHECK(m2.theta[2] == m.theta[2]);
  CHECK(m2.fullscale == 4095.0f);
  CHECK(m2.uid == m.uid);
  CHECK_THROWS_WITH(dsa::decode_matrix_info(Bytes(51, 0)),
                    Catch::Contains("matrix info: payload of 51 bytes, expected 52"));
  CHECK_THROWS_AS(dsa::decode_sensor_info(Bytes(13, 0)), dsa::ProtocolError);
  CHECK_THROWS_AS(dsa::decode_controller_info(Bytes(17, 0)), dsa::ProtocolError);
}

TEST_CASE("DSACON32m codec: frames raw and RLE, and their edge cases", "[drivers][codec]") {
  std::vector<std::uint16_t> t = {0, 0, 0, 5, 5, 4095, 7};
  for (const bool rle : {false, true}) {
    const dsa::RawFrame f = dsa::decode_frame(dsa::encode_frame(1234, t, rle), t.size());
    CHECK(f.timestamp_ms == 1234);
    CHECK(f.texels == t);
    CHECK((f.flags & 1) == (rle ? 1 : 0));
  }
  // Runs longer than 15 split into several units.
  const std::vector<std::uint16_t> zeros(40, 0);
  const Bytes z = dsa::encode_frame(0, zeros, true);
  CHECK(z.size() == 5 + 2 * 3);  // 15 + 15 + 10
  CHECK(dsa::decode_frame(z, 40).texels == zeros);
  // A unit with count 0 adds nothing (SDHLibrary decodes it so).
  Bytes with_empty = dsa::encode_frame(0, std::vector<std::uint16_t>{9, 9}, true);
  with_empty.push_back(0x33);
  with_empty.push_back(0x03);  // value 0x333, count 0
  CHECK(dsa::decode_frame(with_empty, 2).texels == std::vector<std::uint16_t>{9, 9});
  // Too many, too few, odd bytes, short header, values over 12 bits for RLE.
  CHECK_THROWS_WITH(dsa::decode_frame(z, 39), Catch::Contains("runs past 39"));
  CHECK_THROWS_WITH(dsa::decode_frame(z, 41), Catch::Contains("holds 40 tactels, expected 41"));
  Bytes odd = z;
  odd.push_back(0);
  CHECK_THROWS_WITH(dsa::decode_frame(odd, 40), Catch::Contains("whole number"));
  CHECK_THROWS_WITH(dsa::decode_frame(Bytes{1, 2, 3}, 1), Catch::Contains("5-byte header"));
  CHECK_THROWS_WITH(dsa::decode_frame(dsa::encode_frame(0, t, false), 6),
                    Catch::Contains("raw body of 14 bytes, expected 12"));
  CHECK_THROWS_AS(dsa::encode_frame(0, std::vector<std::uint16_t>{4096}, true),
                  std::invalid_argument);
}

TEST_CASE("DSACON32m parser: every split, garbage, corruption, oversize", "[drivers][codec]") {
  const Bytes a = dsa::encode_packet(0x00, dsa::encode_frame(7, ramp(0, 84), true));
  const Bytes b = dsa::encode_query_sensor_info();
  const Bytes c = dsa::encode_packet(0x01, dsa::encode_controller_info({}));
  Bytes stream;
  for (const Bytes* p : {&a, &b, &c}) stream.insert(stream.end(), p->begin(), p->end());

  SECTION("split at every byte (and byte by byte)") {
    for (std::size_t cut = 0; cut <= stream.size(); ++cut) {
      dsa::Parser p;
      p.feed(std::span(stream).first(cut));
      p.feed(std::span(stream).subspan(cut));
      const auto got = parse_all(p);
      REQUIRE(got.size() == 3);
      CHECK(got[0].id == 0x00);
      CHECK(got[1].id == 0x02);
      CHECK(got[2].id == 0x01);
      CHECK(p.stats().skipped_bytes == 0);
    }
    dsa::Parser p;
    for (const std::uint8_t byte : stream) p.feed(std::span(&byte, 1));
    CHECK(parse_all(p).size() == 3);
  }
  SECTION("garbage before and between packets, including stray 0xAA bytes") {
    Bytes g = hex("0011aaaa22aa");
    g.insert(g.end(), a.begin(), a.end());
    for (const std::uint8_t x : hex("aa1b5b356eaaaaaa")) g.push_back(x);  // a 4th 0xAA too
    g.insert(g.end(), b.begin(), b.end());
    dsa::Parser p;
    p.feed(g);
    const auto got = parse_all(p);
    REQUIRE(got.size() == 2);
    CHECK(got[0].payload == Bytes(a.begin() + 6, a.end() - 2));
    CHECK(got[1].id == 0x02);
    CHECK(p.stats().skipped_bytes > 0);
  }
  SECTION("a corrupted CRC drops that packet only") {
    Bytes bad = stream;
    bad[a.size() - 1] ^= 0x40;  // the last CRC byte of the first packet
    dsa::Parser p;
    p.feed(bad);
    const auto got = parse_all(p);
    REQUIRE(got.size() == 2);
    CHECK(got[0].id == 0x02);
    CHECK(p.stats().crc_errors == 1);
  }
  SECTION("a flipped payload bit is caught at every position") {
    for (std::size_t i = 6; i < a.size() - 2; ++i) {
      Bytes bad = a;
      bad[i] ^= 0x01;
      dsa::Parser p;
      p.feed(bad);
      REQUIRE(p.pending() == 0);
    }
  }
  SECTION("an oversized length is refused, the next packet still found") {
    Bytes big = hex("aaaaaa00ffff");
    big.insert(big.end(), b.begin(), b.end());
    dsa::Parser p(1000);
    p.feed(big);
    const auto got = parse_all(p);
    REQUIRE(got.size() == 1);
    CHECK(got[0].id == 0x02);
    CHECK(p.stats().oversized == 1);
  }
  SECTION("a truncated packet waits, reset() forgets it") {
    dsa::Parser p;
    p.feed(std::span(a).first(a.size() - 1));
    CHECK(p.pending() == 0);
    CHECK(p.buffered() == a.size() - 1);
    p.reset();
    p.feed(b);
    CHECK(parse_all(p).size() == 1);
  }
}

TEST_CASE("DsaconDevice over loopback: handshake, streaming, stop, frames intact",
          "[drivers][device]") {
  Rig rig(fast(), [](std::uint64_t i) { return ramp(i, 486); });
  td::DsaconDevice dev(std::move(*rig.host), {.reply_timeout = td::Timeout(500)});
  dev.open();
  CHECK(dev.controller_info().sw_version == 288);
  CHECK(dev.sensor_info().matrices == 6);
  REQUIRE(dev.matrices().size() == 6);
  CHECK(dev.cells() == 486);
  dev.start();
  for (int k = 0; k < 20; ++k) {
    const auto f = dev.read_frame();
    REQUIRE(f);
    REQUIRE(f->matrices.size() == 6);
    CHECK(f->matrices[0].rows() == 14);
    CHECK(f->matrices[1].rows() == 13);
    CHECK(f->matrices[0].cols() == 6);
    // The frame index is recoverable from the clock: its tactels are the ramp of that index.
    const std::uint64_t index = f->device_time_ms / 2;
    const auto want = ramp(index, 486);
    CHECK(f->matrices[0](0, 1) == want[1]);
    CHECK(f->matrices[5](12, 5) == want[485]);
    CHECK(f->sequence == std::uint64_t(k));
  }
  dev.stop();
  CHECK_FALSE(rig.emulator.streaming());
  const auto s = dev.stats();
  CHECK(s.frames >= 20);
  CHECK(s.dropped_frames == 0);
  CHECK(s.link.crc_errors == 0);
  dev.close();
}

TEST_CASE("DsaconDevice: a controller left streaming is stopped at open", "[drivers][device]") {
  td::EmulatorConfig cfg = fast();
  cfg.streaming_at_start = true;
  Rig rig(cfg);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));  // frames pile up
  td::DsaconDevice dev(std::move(*rig.host));
  dev.open();
  CHECK_FALSE(rig.emulator.streaming());
  CHECK(dev.stats().discarded_frames > 0);
  CHECK(dev.cells() == 486);
}

TEST_CASE("DsaconDevice: dropped and corrupted frames are counted, never delivered half",
          "[drivers][device]") {
  // Scripted controller: replies, then frames 0..9 with frame 4 missing and frame 7's CRC
  // broken; then a disconnect in the middle of frame 10. (The ends are named, not structured
  // bindings, because the responder threads' lambdas capture `device`: clang before 16 cannot
  // capture a structured binding.)
  auto ends = td::LoopbackTransport::pair();
  td::LoopbackTransport& host = ends.first;
  td::LoopbackTransport& device = ends.second;
  device.open();
  td::EmulatorConfig cfg = fast();
  td::DsaconEmulator emu(cfg, [](std::uint64_t i) { return ramp(i, 486); });
  td::DsaconDevice dev(std::move(host),
                       {.reply_timeout = td::Timeout(300), .frame_timeout = td::Timeout(100)});
  std::thread responder([&] {
    std::uint8_t buf[256];
    for (int replies = 0; replies < 10;) {  // stop + controller + sensor + 6 matrices + start
      const std::size_t n = device.read(buf, td::Timeout(1000));
      const auto r = emu.receive(std::span<const std::uint8_t>(buf, n));
      if (!r.empty()) {
        device.write(r);
        ++replies;
      }
    }
  });
  dev.open();
  dev.start();
  responder.join();
  for (int i = 0; i < 10; ++i) {
    Bytes f = emu.next_frame();
    if (i == 4) continue;
    if (i == 7) f[f.size() - 1] ^= 0xFF;
    device.write(f);
  }
  std::vector<std::uint64_t> seq;
  while (auto f = dev.read_frame()) seq.push_back(f->sequence);
  CHECK(seq == std::vector<std::uint64_t>{0, 1, 2, 3, 5, 6, 8, 9});
  CHECK(dev.stats().dropped_frames == 2);
  CHECK(dev.stats().link.crc_errors == 1);

  const Bytes half = emu.next_frame();
  device.write(std::span(half).first(half.size() / 2));
  CHECK_FALSE(dev.read_frame());  // half a frame is not a frame
  device.disconnect();
  CHECK_THROWS_AS(dev.read_frame(), td::TransportError);
  CHECK_FALSE(dev.is_open());

  // Reopen: a fresh controller on the same link answers the handshake again.
  td::DsaconEmulator again(cfg);
  std::thread responder2([&] {
    std::uint8_t buf[256];
    device.open();
    for (int replies = 0; replies < 9;) {
      const std::size_t n = device.read(buf, td::Timeout(1000));
      const auto r = again.receive(std::span<const std::uint8_t>(buf, n));
      if (!r.empty()) {
        device.write(r);
        ++replies;
      }
    }
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  dev.open();
  responder2.join();
  CHECK(dev.is_open());
  CHECK(dev.cells() == 486);
}

TEST_CASE("DsaconDevice: timeouts and refusals are reported", "[drivers][device]") {
  auto [host, device] = td::LoopbackTransport::pair();
  device.open();  // nobody answers
  td::DsaconDevice dev(std::move(host), {.reply_timeout = td::Timeout(20), .open_attempts = 2});
  CHECK_THROWS_WITH(dev.open(), Catch::Contains("no reply to command 0x03"));
  CHECK_THROWS_AS(dev.read_frame(), td::TransportError);  // not open
}

TEST_CASE("Sessions: recorded through the device, replayed byte-exact, checked",
          "[drivers][session]") {
  std::vector<td::SessionChunk> recording;
  std::vector<td::TactileFrame> live;
  {
    Rig rig(fast(), [](std::uint64_t i) { return ramp(i, 486); });
    td::DsaconDevice dev(td::RecordingTransport(std::move(*rig.host)));
    dev.open();
    dev.start();
    for (int k = 0; k < 5; ++k) live.push_back(*dev.read_frame());
    dev.stop();
    dev.close();
    recording = dev.transport().chunks();
  }
  const std::string text = td::format_session(recording);
  const auto parsed = td::parse_session(text);
  REQUIRE(parsed.size() == recording.size());
  CHECK(td::format_session(parsed) == text);

  td::DsaconDevice replay(td::ReplayTransport(parsed), {.frame_timeout = td::Timeout(10)});
  replay.open();
  replay.start();
  for (const auto& want : live) {
    const auto f = replay.read_frame();
    REQUIRE(f);
    CHECK(f->device_time_ms == want.device_time_ms);
    CHECK((f->matrices[2] == want.matrices[2]).all());
  }
  // The emulator streams on its own thread, so a read of the live device may have carried a
  // frame past the fifth before the stop (more often on a loaded machine): the sections below
  // compare with what the recording holds, not with 5.
  int recorded = static_cast<int>(live.size());
  while (replay.read_frame()) ++recorded;
  REQUIRE(recorded >= 5);

  SECTION("a host that writes something else is caught") {
    td::ReplayTransport r(parsed);
    r.open();
    const Bytes other = dsa::encode_query_sensor_info();  // the recording starts with a stop
    CHECK_THROWS_WITH(r.write(other, td::Timeout(0)),
                      Catch::Contains("differs from the recording at chunk 1, byte 3"));
  }
  SECTION("a damaged end keeps every chunk before it") {
    const auto prefix = td::parse_session_prefix(text + "9.5 < abc\n", "s");
    CHECK_THAT(prefix.error, Catch::Contains("hex bytes must be"));
    CHECK_THAT(prefix.error, Catch::Contains("s:" + std::to_string(recording.size() + 2) + ":"));
    REQUIRE(prefix.chunks.size() == parsed.size());
    CHECK(prefix.chunks.back().line == parsed.size() + 1);
    td::DsaconDevice again(td::ReplayTransport(prefix.chunks), {.frame_timeout = td::Timeout(10)});
    again.open();
    again.start();
    int frames = 0;
    while (again.read_frame()) ++frames;
    CHECK(frames == recorded);
    const std::string why =
        td::replay_shortfall(again.transport(), again.unparsed_bytes(), prefix.error);
    CHECK_THAT(why, Catch::Contains("the chunks before it were replayed"));
    CHECK(td::parse_session_prefix(text).error.empty());
  }
  SECTION("a flipped direction marker is reported as a replay out of step") {
    // The device chunk that carries the third frame's bytes, marked as if the host sent it.
    std::vector<td::SessionChunk> flipped = parsed;
    std::size_t last_host = 0;
    for (std::size_t i = 0; i < flipped.size(); ++i) {
      if (flipped[i].to_device) last_host = i;
    }
    std::vector<std::size_t> device_chunks;
    for (std::size_t i = 0; i < last_host; ++i) {
      if (!flipped[i].to_device) device_chunks.push_back(i);
    }
    REQUIRE(device_chunks.size() >= 2);
    flipped[device_chunks[device_chunks.size() - 2]].to_device = true;
    td::DsaconDevice bad(td::ReplayTransport(flipped), {.frame_timeout = td::Timeout(10)});
    int frames = 0;
    try {
      bad.open();
      bad.start();
      while (bad.read_frame()) ++frames;
    } catch (const std::exception&) {
      // A flipped handshake chunk fails loudly already; only a silent stall needs the check.
    }
    CHECK(frames < recorded);
    const std::string why = td::replay_shortfall(bad.transport(), bad.unparsed_bytes());
    CHECK_THAT(why, Catch::Contains("replay out of step"));
  }
  SECTION("a session that ends inside a frame says so") {
    std::vector<td::SessionChunk> cut = parsed;
    std::size_t last_host = 0;
    for (std::size_t i = 0; i < cut.size(); ++i) {
      if (cut[i].to_device) last_host = i;
    }
    std::size_t last_device = 0;
    for (std::size_t i = 0; i < last_host; ++i) {
      if (!cut[i].to_device) last_device = i;
    }
    cut.resize(last_device + 1);
    REQUIRE(cut.back().bytes.size() > 3);
    for (int k = 0; k < 3; ++k) cut.back().bytes.pop_back();  // the last packet loses its end
    td::DsaconDevice truncated(td::ReplayTransport(cut), {.frame_timeout = td::Timeout(10)});
    truncated.open();
    truncated.start();
    int frames = 0;
    while (truncated.read_frame()) ++frames;
    CHECK(frames < recorded);
    CHECK(truncated.unparsed_bytes() > 0);
    CHECK_THAT(td::replay_shortfall(truncated.transport(), truncated.unparsed_bytes()),
               Catch::Contains("the last packet is cut off"));
  }
  SECTION("malformed session files are refused with the line") {
    CHECK_THROWS_WITH(td::parse_session("", "s"), Catch::Contains("s:1: empty"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 2\n", "s"), Catch::Contains("s:1:"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 1\n0.1 > aag0\n", "s"),
                      Catch::Contains("s:2: 'g' at column 9 is not a hex digit"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 1\n0.1 > abc\n", "s"),
                      Catch::Contains("s:2: hex bytes must be"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 1\n# c\n0.2 < 00\n0.1 < 00\n", "s"),
                      Catch::Contains("s:4: time goes backwards"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 1\nnan < 00\n", "s"),
                      Catch::Contains("s:2: time 'nan'"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 1\n0 = 00\n", "s"),
                      Catch::Contains("s:2: direction"));
    CHECK_THROWS_WITH(td::parse_session("taxel-session 1\n0\n", "s"), Catch::Contains("s:2:"));
  }
}

TEST_CASE("SerialTransport against a pseudo-terminal with a fake controller thread",
          "[drivers][serial]") {
  int master = -1, slave = -1;
  char name[256] = {};
  REQUIRE(::openpty(&master, &slave, name, nullptr, nullptr) == 0);
  ::close(slave);  // the transport opens it by name
  td::DsaconEmulator emu(fast(), [](std::uint64_t i) { return ramp(i, 486); });
  std::atomic<bool> stop{false};
  std::thread controller([&] {
    std::uint8_t buf[512];
    while (!stop) {
      pollfd p{master, POLLIN, 0};
      if (::poll(&p, 1, 2) > 0 && (p.revents & POLLIN)) {
        const ssize_t n = ::read(master, buf, sizeof buf);
        if (n <= 0) continue;
        const auto r = emu.receive(std::span<const std::uint8_t>(buf, std::size_t(n)));
        if (!r.empty()) (void)!::write(master, r.data(), r.size());
      }
      if (emu.streaming()) {
        const auto f = emu.next_frame();
        (void)!::write(master, f.data(), f.size());
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
      }
    }
  });
  {
    td::DsaconDevice dev(td::SerialTransport(name, 115200));
    dev.open();
    CHECK(dev.cells() == 486);
    dev.start();
    for (int k = 0; k < 10; ++k) {
      const auto f = dev.read_frame();
      REQUIRE(f);
      CHECK(f->matrices[4](3, 2) == ramp(f->device_time_ms / 2, 486)[324 + 3 * 6 + 2]);
    }
    dev.stop();
    CHECK_FALSE(emu.streaming());
  }
  stop = true;
  controller.join();
  ::close(master);
  // The other end gone: reads report a lost device; an unknown path cannot open.
  td::SerialTransport missing("/nonexistent/ttyDSA");
  CHECK_THROWS_WITH(missing.open(), Catch::Contains("/nonexistent/ttyDSA: cannot open"));
  td::SerialTransport not_a_tty("/dev/null");
  CHECK_THROWS_WITH(not_a_tty.open(), Catch::Contains("not a serial port"));
}

TEST_CASE("Frames to contacts and images", "[drivers][convert]") {
  // One 14x6 matrix pressed flat: every tactel reads 1000 of 4095 with a 3 mm full scale.
  dsa::MatrixInfo m = td::sdh2_matrices()[0];
  td::TactileFrame f;
  f.device_time_ms = 500;
  f.matrices.push_back(td::TexelMatrix::Constant(14, 6, 1000));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = taxel::Vec3d(0.1, 0, 0);
  std::vector<taxel::Contact<double>> contacts;
  const std::vector<dsa::MatrixInfo> ms{m};
  const std::vector<Eigen::Isometry3d> poses{pose};
  CHECK(td::frame_contacts(f, ms, poses, contacts) == 84);
  // The depth of 1000 counts less the censoring correction of the default calibration
  // (0.3 mm noise, threshold 8), evaluated at the depth the pad-wide quadric gives, which for a
  // flat press is the corrected depth itself: d = m - sigma * lambda((t - d) / sigma), lambda
  // the inverse Mills ratio phi(a) / (1 - Phi(a)), solved here by fixed-point iteration. The
  // model's second-order (Jensen) term, largest at the pad's corners (the highest leverage in
  // the fit), moves it deeper by less than 4 um.
  const double dq = 3e-3 / 4095, t = 7.5 * dq, m_depth = 1000 * dq;
  const auto correction = [&](double d) {
    const double a = (t - d) / 0.3e-3;
    return 0.3e-3 * std::exp(-0.5 * a * a) / std::sqrt(2 * M_PI) /
           (0.5 * std::erfc(a / std::sqrt(2.0)));
  };
  double depth = m_depth;
  for (int i = 0; i < 50; ++i) depth = m_depth - correction(depth);
  for (const auto& c : contacts) {
    CHECK(-c.position.z() >= depth - 1e-9);
    CHECK(-c.position.z() <= depth + 4e-6);
    CHECK(c.time == 0.5);
  }
  SECTION("the drivers' contacts are the simulator's on the same readings") {
    taxel::sim::PadReading r;
    r.counts = f.matrices[0];
    r.believed_pose = pose;
    std::vector<taxel::Contact<double>> sim_contacts;
    taxel::sim::pad_contacts(r, td::sensor_model(m), taxel::sim::ContactMode::per_tactel, 0.5,
                             sim_contacts);
    REQUIRE(sim_contacts.size() == contacts.size());
    for (std::size_t i = 0; i < contacts.size(); ++i) {
      CHECK(sim_contacts[i].position == contacts[i].position);
      CHECK(sim_contacts[i].covariance == contacts[i].covariance);
      CHECK(*sim_contacts[i].normal == *contacts[i].normal);
    }
  }
  taxel::fusion::ContactCloud<taxel::fusion::Kalman<double>> cloud({.association_radius = 5e-3});
  CHECK(cloud.insert(std::span<const taxel::Contact<double>>(contacts)).rejected == 0);
  contacts.clear();
  CHECK(td::frame_contacts(f, ms, poses, contacts, taxel::sim::ContactMode::per_pad) == 1);
  CHECK(contacts[0].position.x() == Approx(0.1));
  const auto img = td::frame_image(f, 0);
  CHECK(img.rows() == 14);
  CHECK(img(3, 3) == 1000.0);
  CHECK_THROWS_AS(td::frame_image(f, 1), std::out_of_range);
  const std::vector<Eigen::Isometry3d> none;
  CHECK_THROWS_AS(td::frame_contacts(f, ms, none, contacts), std::invalid_argument);
}
