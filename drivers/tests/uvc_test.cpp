// SPDX-License-Identifier: MIT
// The UVC camera driver without a camera: its YUYV conversion against BT.601's closed form, and
// the errors for a missing device and for files that are not V4L2 capture devices. Capturing
// frames needs a camera (or a kernel's vivid test driver), which the tests cannot assume.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <taxel/drivers/uvc_camera.hpp>
#include <vector>

namespace td = taxel::drivers;

TEST_CASE("UVC YUYV frames become RGB by ITU-R BT.601 (limited range)", "[uvc]") {
  // Two pixel pairs: black and white at neutral chroma, then a red-ish and a blue-ish pair.
  const std::vector<std::uint8_t> yuyv = {16, 128, 235, 128, 81, 90, 145, 240};
  taxel::io::RgbImage rgb;
  td::yuyv_to_rgb(yuyv.data(), 4, 1, rgb);
  REQUIRE(rgb.rows == 1);
  REQUIRE(rgb.cols == 4);
  const auto expect = [&](int px, double y, double u, double v) {
    const double c = 1.164 * (y - 16), r = c + 1.596 * (v - 128),
                 g = c - 0.392 * (u - 128) - 0.813 * (v - 128), b = c + 2.017 * (u - 128);
    const auto q = [](double x) {
      return static_cast<int>(std::lround(std::clamp(x, 0.0, 255.0)));
    };
    CAPTURE(px);
    CHECK(int(rgb.data[std::size_t(px) * 3 + 0]) == q(r));
    CHECK(int(rgb.data[std::size_t(px) * 3 + 1]) == q(g));
    CHECK(int(rgb.data[std::size_t(px) * 3 + 2]) == q(b));
  };
  expect(0, 16, 128, 128);
  expect(1, 235, 128, 128);
  expect(2, 81, 90, 240);
  expect(3, 145, 90, 240);
  CHECK(rgb.data[0] == 0);
  CHECK(rgb.data[3] == 255);  // Y = 235 is full white
}

TEST_CASE("UVC cameras that are not there are refused with the reason", "[uvc]") {
  CHECK_THROWS_WITH(td::UvcCamera("/nonexistent/video9"), Catch::Contains("/nonexistent/video9") &&
                                                              Catch::Contains("cannot open") &&
                                                              Catch::Contains("ls /dev/video*"));
  // A character device that is no camera, and a regular file.
  CHECK_THROWS_WITH(td::UvcCamera("/dev/null"), Catch::Contains("is not a Video4Linux2 device"));
  const auto file = std::filesystem::temp_directory_path() / "taxel_uvc_not_a_camera";
  std::FILE* f = std::fopen(file.c_str(), "w");
  REQUIRE(f != nullptr);
  std::fclose(f);
  CHECK_THROWS_WITH(td::UvcCamera(file.string()), Catch::Contains("is not a Video4Linux2 device"));
  std::filesystem::remove(file);
  CHECK_THROWS_WITH(td::UvcCamera("/dev/null", {.buffers = 1}), Catch::Contains("buffers"));
}
