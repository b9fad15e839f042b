// SPDX-License-Identifier: MIT
// Tests of readings as users bring them: numpy .npy stacks (io/npy.hpp), pad poses per frame
// (io/pad_poses_csv.hpp) and the stack-to-contacts conversion (sensor/readings.hpp), which
// must give the simulator's own contacts from its readings and poses.
#include <catch2/catch.hpp>
#include <cstring>
#include <string>
#include <taxel/io/npy.hpp>
#include <taxel/io/pad_poses_csv.hpp>
#include <taxel/sensor/readings.hpp>
#include <taxel/sim.hpp>

namespace tio = taxel::io;
namespace tsn = taxel::sensor;

namespace {

// A .npy file as numpy writes it: magic, version, little-endian header length, the header dict
// padded with spaces to a multiple of 64 bytes and ended by a newline, then the data.
std::string npy(const std::string& dict, const std::string& data, int major = 1) {
  std::string header = dict;
  const std::size_t pre = major == 1 ? 10 : 12;
  while ((pre + header.size() + 1) % 64 != 0) header.push_back(' ');
  header.push_back('\n');
  std::string out("\x93NUMPY", 6);
  out.push_back(static_cast<char>(major));
  out.push_back('\0');
  const std::size_t n = header.size();
  out.push_back(static_cast<char>(n & 0xFF));
  out.push_back(static_cast<char>((n >> 8) & 0xFF));
  if (major != 1) out.append(2, '\0');
  return out + header + data;
}

template <class T>
std::string bytes_of(std::initializer_list<T> values, bool big = false) {
  std::string out;
  for (const T v : values) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big) std::reverse(b, b + sizeof(T));
    out.append(b, sizeof(T));
  }
  return out;
}

}  // namespace

TEST_CASE("npy: the dtypes numpy writes for readings, both byte orders, versions 1 and 2",
          "[io][npy]") {
  const auto a =
      tio::parse_npy_u16(npy("{'descr': '<u2', 'fortran_order': False, 'shape': (2, 3), }",
                             bytes_of<std::uint16_t>({0, 1, 2, 300, 4095, 65535})));
  CHECK(a.shape == std::vector<std::size_t>{2, 3});
  CHECK(a.values == std::vector<std::uint16_t>{0, 1, 2, 300, 4095, 65535});
  const auto b = tio::parse_npy_u16(npy("{'descr': '>i4', 'fortran_order': False, 'shape': (3,), }",
                                        bytes_of<std::int32_t>({7, 0, 4000}, true), 2));
  CHECK(b.shape == std::vector<std::size_t>{3});
  CHECK(b.values == std::vector<std::uint16_t>{7, 0, 4000});
  const auto c =
      tio::parse_npy_u16(npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1, 2, 1, 1), }",
                             bytes_of<double>({12.0, 0.0})));
  CHECK(c.shape == std::vector<std::size_t>{1, 2, 1, 1});
  CHECK(c.values == std::vector<std::uint16_t>{12, 0});
  const auto d = tio::parse_npy_u16(
      npy("{'descr': '|u1', 'fortran_order': False, 'shape': (0, 14, 6), }", ""));
  CHECK(d.values.empty());
  // Fortran order (np.asfortranarray, or a transposed array saved as it is): the first index
  // varies fastest in the file; the values come back in C order. A (2, 3, 2) array whose value
  // at (i, j, k) is 100 i + 10 j + k.
  std::vector<std::uint16_t> column_major, row_major;
  for (int k = 0; k < 2; ++k) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 2; ++i) column_major.push_back(std::uint16_t(100 * i + 10 * j + k));
    }
  }
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) {
      for (int k = 0; k < 2; ++k) row_major.push_back(std::uint16_t(100 * i + 10 * j + k));
    }
  }
  std::string data;
  for (const std::uint16_t v : column_major) data += bytes_of<std::uint16_t>({v}, true);
  const auto f = tio::parse_npy_u16(
      npy("{'descr': '>u2', 'fortran_order': True, 'shape': (2, 3, 2), }", data));
  CHECK(f.shape == std::vector<std::size_t>{2, 3, 2});
  CHECK(f.values == row_major);
  // The encoder's output reads back and has numpy's layout.
  const std::size_t shape[3] = {2, 1, 3};
  const std::uint16_t vals[6] = {1, 2, 3, 4, 5, 65535};
  const std::string enc = tio::encode_npy_u16(shape, vals);
  CHECK(enc.find("{'descr': '<u2', 'fortran_order': False, 'shape': (2, 1, 3), }") == 10);
  CHECK((enc.size() - 12) % 64 == 0);  // data aligned to 64 bytes
  const auto back = tio::parse_npy_u16(enc);
  CHECK(back.shape == std::vector<std::size_t>{2, 1, 3});
  CHECK(back.values == std::vector<std::uint16_t>(vals, vals + 6));
  const std::size_t one[1] = {2};
  const std::uint16_t two[2] = {9, 8};
  CHECK(tio::encode_npy_u16(one, two).find("'shape': (2,)") != std::string::npos);
}

TEST_CASE("npy: malformed files and values that are no readings are refused with the reason",
          "[io][npy]") {
  const auto refused = [](const std::string& bytes, const std::string& why) {
    try {
      (void)tio::parse_npy_u16(bytes, "f.npy");
      FAIL("accepted: " << why);
    } catch (const taxel::IoError& e) {
      INFO(e.what());
      CHECK(std::string(e.what()).find("f.npy: ") == 0);
      CHECK(std::string(e.what()).find(why) != std::string::npos);
    }
  };
  const std::string u2 = "{'descr': '<u2', 'fortran_order': False, 'shape': (2,), }";
  refused("PK\x03\x04 not numpy", "not a .npy file");
  refused(npy(u2, bytes_of<std::uint16_t>({1})), "needs 4 data bytes, the file has 2");
  refused(npy(u2, bytes_of<std::uint16_t>({1, 2, 3})), "needs 4 data bytes, the file has 6");
  refused(npy(u2, "").substr(0, 30), "byte 10: truncated header");
  refused(
      npy("{'descr': '<u2', 'fortran_order': 1, 'shape': (2,), }", bytes_of<std::uint16_t>({1, 2})),
      "fortran_order must be True or False");
  refused(npy("{'descr': '<c16', 'fortran_order': False, 'shape': (1,), }", std::string(16, '\0')),
          "unsupported dtype '<c16'");
  refused(npy("{'descr': '<i2', 'fortran_order': False, 'shape': (2,), }",
              bytes_of<std::int16_t>({3, -1})),
          "value -1.000000 at flat index 1");
  refused(npy("{'descr': '<u4', 'fortran_order': False, 'shape': (1,), }",
              bytes_of<std::uint32_t>({70000})),
          "at flat index 0 is not a reading");
  refused(npy("{'descr': '<f4', 'fortran_order': False, 'shape': (1,), }", bytes_of<float>({1.5f})),
          "is not a reading");
  refused(npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }",
              bytes_of<double>({std::nan("")})),
          "is not a reading");
  refused(
      npy("{'descr': '<u2', 'fortran_order': False, 'shape': (99999999999, 99999999999), }", ""),
      "shape");
  refused(npy("{'descr': '<u2', 'fortran_order': False}", ""), "header has no 'shape'");
  CHECK_THROWS_AS(tio::read_npy_u16("/nonexistent/readings.npy"), taxel::IoError);
}

TEST_CASE("pad poses CSV: round trip, the drivers' format, and bad rows refused", "[io][poses]") {
  std::vector<tio::PadPose> poses;
  for (std::size_t f = 0; f < 3; ++f) {
    for (std::size_t p = 0; p < 2; ++p) {
      tio::PadPose x;
      x.frame = f;
      x.pad = p;
      x.time = 0.001 * double(f);
      x.pose.linear() =
          Eigen::AngleAxisd(0.3 * double(f + p) + 0.1, taxel::Vec3d(1, 2, 3).normalized())
              .toRotationMatrix();
      x.pose.translation() = taxel::Vec3d(0.1 * double(f), -0.02, 0.5 + double(p));
      poses.push_back(x);
    }
  }
  const auto back = tio::parse_pad_poses_csv(tio::encode_pad_poses_csv(poses));
  REQUIRE(back.size() == poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    CHECK(back[i].frame == poses[i].frame);
    CHECK(back[i].pad == poses[i].pad);
    CHECK(back[i].time == poses[i].time);
    CHECK((back[i].pose.matrix() - poses[i].pose.matrix()).norm() < 1e-15);
  }
  // Columns in any order, spaces, comments; the drivers' time_ms / matrix columns.
  const auto d = tio::parse_pad_poses_csv(
      "# from taxel-record\ntime_ms,matrix,x,y,z,qw,qx,qy,qz\n40,0,1,2,3,1,0,0,0\n"
      "40,1,1,2,3,0,1,0,0\n73,0,0,0,0,1,0,0,0\n");
  REQUIRE(d.size() == 3);
  CHECK(d[0].frame == 0);
  CHECK(d[1].frame == 0);
  CHECK(d[1].pad == 1);
  CHECK(d[2].frame == 1);
  CHECK(d[2].time == Approx(0.073));
  CHECK(d[1].pose.linear()(1, 1) == Approx(-1.0));  // 180 degrees about x
  const auto e =
      tio::parse_pad_poses_csv("qz, qy, qx, qw, z, y, x, pad, frame\n0,0,0,1,3,2,1,4,5\n");
  CHECK(e[0].pad == 4);
  CHECK(e[0].frame == 5);
  CHECK(e[0].pose.translation() == taxel::Vec3d(1, 2, 3));
  CHECK(std::isnan(e[0].time));

  const auto refused = [](const std::string& text, const std::string& why) {
    try {
      (void)tio::parse_pad_poses_csv(text, "p.csv");
      FAIL("accepted: " << why);
    } catch (const taxel::IoError& err) {
      INFO(err.what());
      CHECK(std::string(err.what()).find(why) != std::string::npos);
    }
  };
  const std::string h = "frame,pad,x,y,z,qw,qx,qy,qz\n";
  refused("", "empty");
  refused("frame,pad,x,y,z,qw,qx,qy\n", "p.csv:1: the header needs the columns");
  refused(h + "0,0,0,0,0,1,0,0\n", "p.csv:2: 8 cells, the header has 9");
  refused(h + "0,0,0,nan,0,1,0,0,0\n", "p.csv:2: column 4: 'nan' is not a finite number");
  refused(h + "0,0,0,0,0,0.5,0,0,0\n", "p.csv:2: the quaternion");
  refused(h + "-1,0,0,0,0,1,0,0,0\n", "frame must be a whole number");
  refused(h + "0,1.5,0,0,0,1,0,0,0\n", "pad must be a whole number");
  refused(h + "0,0,0,0,0,1,0,0,0\n0,0,0,0,0,1,0,0,0\n", "p.csv:3: frame 0, pad 0 has a pose");
  refused("frame,frame,pad\n", "column 'frame' appears twice");
}

TEST_CASE("readings to contacts: the simulator's readings and believed poses give its contacts",
          "[sensor][readings]") {
  for (const auto mode : {tsn::ContactMode::per_tactel, tsn::ContactMode::per_pad}) {
    taxel::sim::ExplorationConfig cfg;
    cfg.contacts.mode = mode;
    cfg.seed = 4;
    const auto ex = taxel::sim::explore_grasps(taxel::sim::Torus(0.04, 0.015), cfg, {.grasps = 2});
    const auto expected = ex.contacts();
    REQUIRE(expected.size() > 100);
    const std::size_t pads = ex.frames[0].pads.size();
    tsn::ReadingStack stack{ex.frames.size(), pads, 14, 6, {}};
    std::vector<tio::PadPose> poses;
    for (std::size_t f = 0; f < ex.frames.size(); ++f) {
      for (std::size_t p = 0; p < pads; ++p) {
        const auto& pad = ex.frames[f].pads[p];
        stack.values.insert(stack.values.end(), pad.counts.data(),
                            pad.counts.data() + pad.counts.size());
        poses.push_back({f, p, ex.frames[f].time, pad.believed_pose});
      }
    }
    // Through the files, as a user would: .npy and CSV.
    const std::size_t shape[4] = {stack.frames, pads, 14, 6};
    const auto npy_stack =
        tsn::ReadingStack::from_npy(tio::parse_npy_u16(tio::encode_npy_u16(shape, stack.values)));
    const auto csv_poses = tio::parse_pad_poses_csv(tio::encode_pad_poses_csv(poses));
    std::vector<taxel::Contact<double>> got;
    const auto summary =
        tsn::contacts_from_readings(npy_stack, csv_poses, cfg.sensor, cfg.contacts, 1000.0, got);
    CHECK(summary.pad_frames == stack.frames * pads);
    CHECK(summary.contacts == expected.size());
    REQUIRE(got.size() == expected.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
      REQUIRE((got[i].position - expected[i].position).norm() < 1e-15);
      REQUIRE((got[i].covariance - expected[i].covariance).norm() < 1e-20);
      REQUIRE((*got[i].normal - *expected[i].normal).norm() < 1e-14);
      REQUIRE(got[i].time == expected[i].time);
    }
  }
}

TEST_CASE("readings to contacts: inconsistent input is refused with the frame and pad",
          "[sensor][readings]") {
  tsn::SensorModel model;
  tsn::ReadingStack stack{2, 1, 14, 6, std::vector<std::uint16_t>(2 * 84, 0)};
  stack.values[84 + 10] = 500;  // frame 1 reads contact
  std::vector<tio::PadPose> poses{{0, 0, 0.0, Eigen::Isometry3d::Identity()}};
  std::vector<taxel::Contact<double>> out;
  const auto why = [&](const tsn::SensorModel& m) {
    try {
      (void)tsn::contacts_from_readings(stack, poses, m, {}, 1000.0, out);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  CHECK(why(model) == "readings: frame 1, pad 0 reads contact but has no pose");
  poses.push_back({1, 0, std::nan(""), Eigen::Isometry3d::Identity()});
  CHECK(why(model) == "accepted");
  REQUIRE(out.size() == 1);
  CHECK(out[0].time == Approx(0.001));  // frame / frame rate when the pose has no time
  poses.push_back({2, 0, 0.0, Eigen::Isometry3d::Identity()});
  CHECK(why(model).find("a pose for frame 2, pad 0, but the stack has 2 frames of 1 pads") !=
        std::string::npos);
  poses.pop_back();
  tsn::SensorModel narrow = model;
  narrow.geometry.cols = 5;
  CHECK(why(narrow) == "readings: the pads have 14 x 6 tactels, the sensor model 14 x 5");
  tsn::SensorModel eight_bit = model;
  eight_bit.levels = 256;
  CHECK(why(eight_bit).find("frame 1 reads 500, above the sensor's largest level 255") !=
        std::string::npos);
  CHECK_THROWS_AS(tsn::ReadingStack::from_npy({{14, 6}, std::vector<std::uint16_t>(84)}),
                  std::invalid_argument);
}
