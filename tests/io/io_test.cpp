// SPDX-License-Identifier: MIT
// Tests of taxel::io image readers and writers: round trips, foreign conventions, and malformed
// inputs that must be refused with the place of the error.
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <algorithm>
#include <bit>
#include <catch2/catch.hpp>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <taxel/io.hpp>
#include <vector>

#if defined(TAXEL_TEST_HAVE_PNG)
#include <zlib.h>
#include <taxel/io/png.hpp>
#endif
#if defined(TAXEL_TEST_HAVE_JPEG)
#include <taxel/io/jpeg.hpp>
#endif

namespace tio = taxel::io;
namespace ti = taxel::image;
using Catch::Matchers::Contains;

namespace {
std::string npy(const std::string& descr, const std::string& shape, const std::string& data,
                bool fortran = false, int version = 1) {
  std::string dict = "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") +
                     ", 'shape': " + shape + ", }\n";
  std::string out("\x93NUMPY", 6);
  out.push_back(static_cast<char>(version));
  out.push_back('\0');
  if (version == 1) {
    out.push_back(static_cast<char>(dict.size() & 0xFF));
    out.push_back(static_cast<char>(dict.size() >> 8));
  } else {
    for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((dict.size() >> (8 * b)) & 0xFF));
  }
  return out + dict + data;
}

ti::ImageD ramp_image(Eigen::Index rows, Eigen::Index cols) {
  ti::ImageD img(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) img(r, c) = static_cast<double>((r * 7 + c * 3) % 256);
  }
  return img;
}
}  // namespace

TEST_CASE("CSV images: round trip and strict errors", "[io]") {
  const ti::ImageD img = ramp_image(4, 5) * 0.25 - 3.0;
  const tio::ImageStack s = tio::parse_image_csv(tio::encode_image_csv(img));
  REQUIRE(s.frames == 1);
  REQUIRE(s.rows == 4);
  REQUIRE(s.cols == 5);
  CHECK((s.frame(0) == img).all());

  const tio::ImageStack t = tio::parse_image_csv("# comment\r\n1, 2,3\r\n\r\n 4 ,5, 6 \n");
  CHECK(t.rows == 2);
  CHECK(t.frame(0)(1, 2) == 6);

  CHECK_THROWS_WITH(tio::parse_image_csv("1,2,3\n4,5\n", "f.csv"),
                    Contains("f.csv:2") && Contains("the first row has 3"));
  CHECK_THROWS_WITH(tio::parse_image_csv("1,2\n3,x\n", "f.csv"),
                    Contains("f.csv:2") && Contains("column 2") && Contains("'x'"));
  CHECK_THROWS_WITH(tio::parse_image_csv("1,,2\n"),
                    Contains("column 2 (pixel row 0, column 1): empty value"));
  // A bad pixel is named by its row and column (0-based) and its text.
  CHECK_THROWS_WITH(
      tio::parse_image_csv("1,2\n3,nan\n", "n.csv"),
      Contains("n.csv:2: column 2 (pixel row 1, column 1): value 'nan' is not finite"));
  CHECK_THROWS_WITH(tio::parse_image_csv("1,inf\n"), Contains("not finite"));
  CHECK_THROWS_WITH(tio::parse_image_csv("1,2 3\n"), Contains("expected ','"));
  // numpy's np.savetxt default: whitespace-separated, exponent notation.
  const tio::ImageStack ws =
      tio::parse_image_csv("1.000000000000000000e+00 2.5e+00\t3\n  4 5 6.0e-01\n");
  REQUIRE((ws.rows == 2 && ws.cols == 3));
  CHECK(ws.frame(0)(0, 1) == 2.5);
  CHECK(ws.frame(0)(1, 2) == 0.6);
  CHECK_THROWS_WITH(tio::parse_image_csv("1 2 3\n4 5\n"), Contains("the first row has 3"));
  CHECK_THROWS_WITH(tio::parse_image_csv("\n# only a comment\n", "e.csv"),
                    Contains("e.csv") && Contains("empty"));
  CHECK_THROWS_AS(tio::parse_image_csv(""), taxel::IoError);
}

TEST_CASE("PGM images: P2 and P5, 8 and 16 bit, stacks, strict errors", "[io]") {
  const ti::ImageD img = ramp_image(6, 9);
  const tio::ImageStack s8 = tio::parse_pgm(tio::encode_pgm(img));
  REQUIRE(s8.rows == 6);
  REQUIRE(s8.cols == 9);
  CHECK((s8.frame(0) == img).all());

  const tio::ImageStack s16 = tio::parse_pgm(tio::encode_pgm(img * 200.0, 0, 65535, 65535));
  CHECK((s16.frame(0) == img * 200.0).all());

  const tio::ImageStack a =
      tio::parse_pgm("P2\n# made by hand\n3 2\n# comment\n15\n0 1 2\n13 14 15\n");
  CHECK(a.rows == 2);
  CHECK(a.frame(0)(1, 2) == 15);

  const std::string two = tio::encode_pgm(img) + tio::encode_pgm(img * 0.5);
  const tio::ImageStack st = tio::parse_pgm(two);
  CHECK(st.frames == 2);
  CHECK((st.frame(1) == (img * 0.5).round()).all());

  std::string truncated = tio::encode_pgm(img);
  truncated.resize(truncated.size() - 5);
  CHECK_THROWS_WITH(tio::parse_pgm(truncated, "t.pgm"),
                    Contains("t.pgm: byte") && Contains("truncated"));
  CHECK_THROWS_WITH(tio::parse_pgm("P2\n2 1\n10\n3 11\n"), Contains("exceeds maxval 10"));
  CHECK_THROWS_WITH(tio::parse_pgm("P6\n2 1\n255\nabcdef"), Contains("expected 'P2' or 'P5'"));
  CHECK_THROWS_WITH(tio::parse_pgm("P5\n99999999 99999999\n255\n"), Contains("exceeds"));
  CHECK_THROWS_WITH(tio::parse_pgm("P5\n0 3\n255\n"), Contains("no pixels"));
  CHECK_THROWS_WITH(tio::parse_pgm("P2\n2 2\n255\n1 2 3"), Contains("file ends before"));
  CHECK_THROWS_WITH(tio::parse_pgm("P5\n2 1\n70000\nab"), Contains("maxval exceeds 65535"));
  CHECK_THROWS_WITH(tio::parse_pgm(tio::encode_pgm(img) + tio::encode_pgm(ramp_image(2, 2))),
                    Contains("frame size differs"));
}

TEST_CASE("NPY images: dtypes, stacks, Fortran order, versions, strict errors", "[io]") {
  const ti::ImageD img = ramp_image(3, 4) - 100.0;
  tio::ImageStack one{1, 3, 4, {img.data(), img.data() + img.size()}};
  const tio::ImageStack back = tio::parse_npy(tio::encode_npy(one));
  CHECK(back.frames == 1);
  CHECK((back.frame(0) == img).all());
  tio::ImageStack three{3, 3, 4, {}};
  for (int f = 0; f < 3; ++f) {
    for (Eigen::Index i = 0; i < img.size(); ++i) three.values.push_back(img.data()[i] * f);
  }
  const tio::ImageStack back3 = tio::parse_npy(tio::encode_npy(three));
  CHECK(back3.frames == 3);
  CHECK(back3.values == three.values);
  // Integer dtypes round-trip exactly and refuse values they cannot hold.
  tio::ImageStack bytes{2, 2, 2, {0, 1, 254, 255, 7, 8, 9, 10}};
  const std::string u1_file = tio::encode_npy(bytes, tio::NpyDtype::u1);
  CHECK(u1_file.find("'descr': '|u1'") != std::string::npos);
  CHECK(u1_file.size() % 64 == 8 % 64);  // 64-byte aligned header + 8 one-byte values
  CHECK(tio::parse_npy(u1_file).values == bytes.values);
  bytes.values[3] = 60000;
  CHECK(tio::parse_npy(tio::encode_npy(bytes, tio::NpyDtype::u2)).values == bytes.values);
  CHECK_THROWS_WITH(tio::encode_npy(bytes, tio::NpyDtype::u1),
                    Contains("at index 3 does not fit dtype |u1"));
  bytes.values[5] = 0.5;
  CHECK_THROWS_WITH(tio::encode_npy(bytes, tio::NpyDtype::u2), Contains("at index 5"));

  // u1 and i2 and f4, hand-made.
  const tio::ImageStack u1 =
      tio::parse_npy(npy("|u1", "(2, 3)", std::string("\x00\x01\x02\xff\x10\x20", 6)));
  CHECK(u1.frame(0)(1, 0) == 255);
  const tio::ImageStack i2 =
      tio::parse_npy(npy("<i2", "(1, 2)", std::string("\xfe\xff\x05\x01", 4)));
  CHECK(i2.frame(0)(0, 0) == -2);
  CHECK(i2.frame(0)(0, 1) == 261);
  const float f[2] = {1.5f, -2.25f};
  const tio::ImageStack f4 =
      tio::parse_npy(npy("<f4", "(2, 1)", std::string(reinterpret_cast<const char*>(f), 8)));
  CHECK(f4.frame(0)(1, 0) == -2.25);
  // Fortran order: bytes column-major.
  const tio::ImageStack fo =
      tio::parse_npy(npy("|u1", "(2, 3)", std::string("\x01\x04\x02\x05\x03\x06", 6), true));
  CHECK(fo.frame(0)(0, 1) == 2);
  CHECK(fo.frame(0)(1, 0) == 4);
  // Format version 2 header.
  CHECK(tio::parse_npy(npy("|u1", "(1, 2)", std::string("\x07\x08", 2), false, 2)).frame(0)(0, 1) ==
        8);

  CHECK_THROWS_WITH(tio::parse_npy("NUMPY....", "x.npy"),
                    Contains("x.npy: byte 0") && Contains("magic"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("|u1", "(2, 3)", "abc")), Contains("truncated"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("|u1", "(1, 2)", "abc")), Contains("1 unexpected bytes"));
  // Big-endian values (numpy's '>' byte order).
  CHECK(
      tio::parse_npy(npy(">f8", "(1, 1)", std::string("\xc0\x02\0\0\0\0\0\0", 8))).frame(0)(0, 0) ==
      -2.25);
  CHECK(tio::parse_npy(npy(">i2", "(1, 1)", std::string("\xff\xfe", 2))).frame(0)(0, 0) == -2);
  CHECK_THROWS_WITH(tio::parse_npy(npy("<c16", "(1, 1)", std::string(16, '\0'))),
                    Contains("unsupported dtype"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("|u1", "(1, 1, 1, 1)", "a")), Contains("dimension"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("|u1", "(4,)", "abcd")), Contains("1 dimension"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("|u1", "(0, 4)", "")), Contains("no pixels"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("|u1", "(99999999999, 4)", "")), Contains("limit"));
  const double nan = std::nan("");
  CHECK_THROWS_WITH(
      tio::parse_npy(npy("<f8", "(1, 1)", std::string(reinterpret_cast<const char*>(&nan), 8))),
      Contains("not finite"));
  // The bad pixel by frame, row and column, in C and in Fortran order: a (2, 2, 3) stack whose
  // element 9 (C order: frame 1, row 1, column 0; Fortran: frame 1, row 0, column 2) is NaN.
  double stack[12] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 0, 10, 11};
  stack[9] = nan;
  const std::string raw(reinterpret_cast<const char*>(stack), sizeof stack);
  CHECK_THROWS_WITH(tio::parse_npy(npy("<f8", "(2, 2, 3)", raw), "s.npy"),
                    Contains("pixel (row 1, column 0) of frame 1 is not finite (nan)"));
  CHECK_THROWS_WITH(tio::parse_npy(npy("<f8", "(2, 2, 3)", raw, true), "s.npy"),
                    Contains("pixel (row 0, column 2) of frame 1 is not finite (nan)"));
  std::string cut = npy("|u1", "(1, 1)", "a");
  cut.resize(20);
  CHECK_THROWS_WITH(tio::parse_npy(cut), Contains("header of"));
}

TEST_CASE("image files by extension, pictures", "[io]") {
  const auto dir = std::filesystem::temp_directory_path() / "taxel_io_test";
  std::filesystem::create_directories(dir);
  const ti::ImageD img = ramp_image(5, 7);
  tio::write_file((dir / "a.PGM").string(), tio::encode_pgm(img));
  tio::write_file((dir / "a.csv").string(), tio::encode_image_csv(img));
  tio::ImageStack st{1, 5, 7, {img.data(), img.data() + img.size()}};
  tio::write_file((dir / "a.npy").string(), tio::encode_npy(st));
  for (const char* name : {"a.PGM", "a.csv", "a.npy"}) {
    CHECK((tio::read_image((dir / name).string()).frame(0) == img).all());
  }
  CHECK_THROWS_WITH(tio::read_image((dir / "a.bmp").string()), Contains("unknown image format"));
  CHECK_THROWS_WITH(tio::read_image((dir / "missing.csv").string()), Contains("cannot open"));

  const tio::RgbImage pic = tio::colorize(img, 0, 255, 3);
  CHECK(pic.rows == 15);
  CHECK(pic.cols == 21);
  const auto lo = tio::ramp(0.0), hi = tio::ramp(1.0);
  CHECK(std::equal(lo.begin(), lo.end(), pic.at(0, 0)));
  CHECK(hi[0] == 253);
  const tio::RgbImage both = tio::side_by_side({pic, pic}, 4);
  CHECK(both.cols == 46);
  const tio::RgbImage tall = tio::stacked({pic, both}, 2);
  CHECK(tall.rows == 15 + 2 + 15);
  CHECK(tall.cols == 46);
  CHECK(std::equal(pic.at(14, 0), pic.at(14, 0) + 21 * 3, tall.at(14, 0)));
  CHECK(std::equal(both.at(0, 0), both.at(0, 0) + 46 * 3, tall.at(17, 0)));
  CHECK(tall.at(16, 0)[0] == 255);  // the gap is white
  CHECK(tio::encode_ppm(both).substr(0, 2) == "P6");
#if defined(TAXEL_TEST_HAVE_PNG)
  tio::write_png((dir / "p.png").string(), both);
  const tio::RgbImage again = tio::read_png((dir / "p.png").string());
  CHECK(again.rows == both.rows);
  CHECK(again.data == both.data);
  CHECK_THROWS_AS(tio::read_png((dir / "a.csv").string()), taxel::IoError);
  CHECK_THROWS_WITH(tio::read_png_image((dir / "p.png").string()),
                    Contains("p.png") && Contains("a colour PNG"));
#endif
  std::filesystem::remove_all(dir);
}

#if defined(TAXEL_TEST_HAVE_PNG)
namespace {
// A greyscale PNG built by hand (signature, IHDR, one zlib IDAT with filter 0 rows, IEND; no
// gamma chunk), independent of libpng's writer: samples big-endian at 16 bits.
std::string grey_png(std::uint32_t width, std::uint32_t height, int bits,
                     const std::vector<unsigned>& samples) {
  const auto be32 = [](std::uint32_t v) {
    return std::string{static_cast<char>(v >> 24), static_cast<char>(v >> 16),
                       static_cast<char>(v >> 8), static_cast<char>(v)};
  };
  const auto chunk = [&](const std::string& type, const std::string& data) {
    const std::string body = type + data;
    const auto crc = static_cast<std::uint32_t>(
        crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
    return be32(static_cast<std::uint32_t>(data.size())) + body + be32(crc);
  };
  std::string raw;
  for (std::uint32_t r = 0; r < height; ++r) {
    raw.push_back('\0');  // filter type 0
    for (std::uint32_t c = 0; c < width; ++c) {
      const unsigned v = samples[r * width + c];
      if (bits == 16) raw.push_back(static_cast<char>(v >> 8));
      raw.push_back(static_cast<char>(v & 0xFF));
    }
  }
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string z(size, '\0');
  REQUIRE(compress(reinterpret_cast<Bytef*>(z.data()), &size,
                   reinterpret_cast<const Bytef*>(raw.data()),
                   static_cast<uLong>(raw.size())) == Z_OK);
  z.resize(size);
  const std::string ihdr =
      be32(width) + be32(height) + std::string{static_cast<char>(bits), 0, 0, 0, 0};
  return std::string("\x89PNG\r\n\x1a\n", 8) + chunk("IHDR", ihdr) + chunk("IDAT", z) +
         chunk("IEND", "");
}
}  // namespace

TEST_CASE("PNG pressure images: 8 and 16-bit greyscale samples as stored", "[io][png]") {
  const auto dir = std::filesystem::temp_directory_path() / "taxel_png_image_test";
  std::filesystem::create_directories(dir);
  const std::vector<unsigned> wide{0, 1, 258, 4095, 40000, 65535};
  tio::write_file((dir / "w.png").string(), grey_png(3, 2, 16, wide));
  const tio::ImageStack w = tio::read_png_image((dir / "w.png").string());
  REQUIRE((w.frames == 1 && w.rows == 2 && w.cols == 3));
  for (std::size_t i = 0; i < wide.size(); ++i) CHECK(w.values[i] == double(wide[i]));
  CHECK(w.frame(0)(1, 0) == 4095);
  const std::vector<unsigned> narrow{0, 7, 128, 255};
  tio::write_file((dir / "n.png").string(), grey_png(2, 2, 8, narrow));
  const tio::ImageStack n = tio::read_png_image((dir / "n.png").string());
  REQUIRE((n.rows == 2 && n.cols == 2));
  for (std::size_t i = 0; i < narrow.size(); ++i) CHECK(n.values[i] == double(narrow[i]));
  std::string cut = grey_png(3, 2, 16, wide);
  cut.resize(cut.size() - 20);
  tio::write_file((dir / "cut.png").string(), cut);
  CHECK_THROWS_WITH(tio::read_png_image((dir / "cut.png").string()),
                    Contains("cut.png") && Contains("PNG read failed"));
  std::filesystem::remove_all(dir);
}
#endif

TEST_CASE("SVG line plots: points, legend, escaping, reversed axis, errors", "[io][svg]") {
  namespace tio = taxel::io;
  const auto count = [](const std::string& s, const std::string& what) {
    std::size_t n = 0;
    for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
  };
  tio::LinePlot plot;
  plot.title = "accuracy <vs> SNR & noise";
  plot.x_label = "SNR (dB)";
  plot.y_label = "accuracy (%)";
  plot.reverse_x = true;
  plot.series.push_back({"conventional", {50, 40, 30}, {90, 80, 70}});
  plot.series.push_back({"hybrid", {50, 40, 30}, {95, std::nan(""), 85}});
  const std::string svg = tio::render_svg(plot);
  CHECK(svg.rfind("<svg ", 0) == 0);
  CHECK(svg.find("</svg>") != std::string::npos);
  CHECK(count(svg, "<circle") == 5);  // the NaN point is left out
  CHECK(count(svg, "<path") == 2);
  CHECK(svg.find("accuracy &lt;vs&gt; SNR &amp; noise") != std::string::npos);
  CHECK(svg.find(">hybrid</text>") != std::string::npos);
  // Reversed x: the first point (x = 50) is drawn left of the last (x = 30).
  const auto cx = [&](std::size_t nth) {
    std::size_t p = 0;
    for (std::size_t i = 0; i <= nth; ++i) p = svg.find("<circle cx=\"", p) + 12;
    return std::stod(svg.substr(p));
  };
  CHECK(cx(0) < cx(2));
  // The NaN breaks the hybrid line into two pieces.
  CHECK(count(svg, " M") == 1);

  tio::LinePlot bad;
  bad.series.push_back({"broken", {1, 2}, {1}});
  CHECK_THROWS_WITH(tio::render_svg(bad), Catch::Matchers::Contains("'broken' has 2 x values"));
  tio::LinePlot empty;
  CHECK(count(tio::render_svg(empty), "<circle") == 0);
}

TEST_CASE("PLY: ASCII and binary round trips, foreign files, strict errors", "[io][ply]") {
  namespace tio = taxel::io;
  taxel::PointCloud<double> cloud;
  for (int i = 0; i < 5; ++i) {
    cloud.points.emplace_back(0.1 * i, -0.25 * i, 1e-3 / (i + 1));
    cloud.normals.emplace_back(0.0, i % 2 ? 1.0 : 0.0, i % 2 ? 0.0 : 1.0);
  }
  cloud.fields.push_back({"observations", {1, 2, 3, 4, 5}});
  cloud.fields.push_back({"covariance_trace", {1e-6, 2e-6, 3.5e-7, 0.0, 1.0 / 3.0}});
  const std::vector<std::array<std::uint32_t, 3>> tris{{0, 1, 2}, {2, 3, 4}};
  for (const auto format : {tio::PlyFormat::ascii, tio::PlyFormat::binary_little_endian}) {
    const tio::PlyData back = tio::parse_ply(tio::encode_ply(cloud, format, tris));
    CHECK(back.cloud.points == cloud.points);  // exact: shortest round-trip text or raw bits
    CHECK(back.cloud.normals == cloud.normals);
    REQUIRE(back.cloud.fields.size() == 2);
    CHECK(back.cloud.fields[1].name == "covariance_trace");
    CHECK(back.cloud.fields[1].values == cloud.fields[1].values);
    CHECK(back.triangles == tris);
  }
  // A foreign file: float and uchar colour properties, a comment, CRLF, a quad face.
  const std::string foreign =
      "ply\r\nformat ascii 1.0\r\ncomment made elsewhere\r\nelement vertex 4\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\nproperty uchar red\r\n"
      "element face 1\r\nproperty list uchar int vertex_index\r\nend_header\r\n"
      "0 0 0 255\r\n1 0 0 0\r\n1 1 0 10\r\n0 1 0 20\r\n4 0 1 2 3\r\n";
  const tio::PlyData f = tio::parse_ply(foreign);
  CHECK(f.cloud.size() == 4);
  CHECK_FALSE(f.cloud.has_normals());
  REQUIRE(f.cloud.field("red") != nullptr);
  CHECK(f.cloud.field("red")->values[0] == 255);
  CHECK(f.triangles.size() == 2);
  // Faces before the vertices, properties in another order, an unrelated element.
  const std::string faces_first =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar uint vertex_indices\n"
      "element camera 1\nproperty float focal\nelement vertex 3\nproperty float z\n"
      "property float intensity\nproperty float x\nproperty float y\nend_header\n"
      "3 2 1 0\n35.0\n1 0.5 0 0\n2 0.5 1 0\n3 0.5 0 1\n";
  const tio::PlyData ff = tio::parse_ply(faces_first);
  CHECK(ff.cloud.points[1] == taxel::Vec3d(1, 0, 2));
  CHECK(ff.cloud.field("intensity")->values[2] == 0.5);
  CHECK(ff.triangles == std::vector<std::array<std::uint32_t, 3>>{{2, 1, 0}});
  CHECK_THROWS_WITH(tio::parse_ply("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar "
                                   "int vertex_indices\nelement vertex 1\nproperty float x\n"
                                   "property float y\nproperty float z\nend_header\n3 0 1 "
                                   "2\n0 0 0\n"),
                    Contains("refers to vertex 1 of 1"));
  // Binary float32 written by hand.
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  for (const float v : {1.5f, -2.0f, 0.25f, 3.0f, 4.0f, 5.0f}) {
    const auto bits = std::bit_cast<std::uint32_t>(v);
    for (int b = 0; b < 4; ++b) bin.push_back(static_cast<char>((bits >> (8 * b)) & 0xFF));
  }
  const tio::PlyData b = tio::parse_ply(bin);
  CHECK(b.cloud.points[0] == taxel::Vec3d(1.5, -2.0, 0.25));
  CHECK(b.cloud.points[1] == taxel::Vec3d(3.0, 4.0, 5.0));

  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\n"
      "property double y\nproperty double z\nend_header\n";
  struct Bad {
    std::string text;
    const char* message;
  };
  const std::vector<Bad> bad{
      {"plx\n", "<ply>:1: not a PLY file"},
      {"ply\nformat ascii 1.0\nelement vertex 1\n", "no end_header"},
      {"ply\nformat binary_big_endian 1.0\nend_header\n", ":2: binary_big_endian"},
      {"ply\nformat ascii 2.0\nend_header\n", ":2: malformed format"},
      {"ply\nelement vertex 1\nproperty double x\nend_header\n0\n", "no format line"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty quad x\nend_header\n",
       ":4: unknown property type 'quad'"},
      {"ply\nformat ascii 1.0\nproperty double x\nend_header\n", ":3: property before any element"},
      {"ply\nformat ascii 1.0\nelement vertex x\nend_header\n", ":3: malformed element"},
      {"ply\nformat ascii 1.0\nwhatever\nend_header\n", ":3: unknown header keyword"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nend_header\n1\n",
       "no x, y and z"},
      {head + "1 2 3\n", ":9: line ends before x"},
      {head + "1 2 3\n4 5\n", ":9: line ends before z"},
      {head + "1 2 3\n4 5 6 7\n", ":9: more values"},
      {head + "1 2 3\n4 x 6\n", ":9: 'x' is not a number"},
      {head + "1 2 3\nnan 5 6\n", ":9: vertex 1 has a non-finite coordinate"},
      {head + "1 2 3\n4 5 6\n7 8 9\n", "data after the last element"},
      {"ply\nformat ascii 1.0\nelement vertex 99999999999\nproperty double x\nproperty double y\n"
       "property double z\nend_header\n0 0 0\n",
       "declares 99999999999 entries"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty double x\nproperty double y\n"
       "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n3 0 1 2\n",
       ":11: face 0 refers to vertex 1 of 1"},
      {"ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
       "property double z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
       "0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
       "fewer than 3 vertices"},
      {"ply\nformat ascii 1.0\nelement vertex 1\nproperty uchar x\nproperty double y\n"
       "property double z\nend_header\n1.5 0 0\n",
       ":8: '1.5' is not an integer"},
      {std::string("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n"
                   "property double y\nproperty double z\nend_header\n") +
           std::string(20, '\0'),
       "too short"},
      {std::string("ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
                   "property float y\nproperty float z\nend_header\n") +
           std::string(13, '\0'),
       "data after the last element"},
  };
  for (const auto& [text, message] : bad) {
    INFO(text);
    CHECK_THROWS_WITH(tio::parse_ply(text), Contains(message));
  }
  // Elements without properties (found by fuzzing: a declared count of 2e9 was walked entry by
  // entry). In binary they hold no bytes and are skipped whatever their count; in ASCII each
  // entry is a line, so the count is bounded by the file.
  {
    const std::string binary =
        std::string(
            "ply\nformat binary_little_endian 1.0\nelement marker 4000000000\n"
            "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
            "end_header\n") +
        std::string(12, '\0');
    const auto d = tio::parse_ply(binary);
    REQUIRE(d.cloud.size() == 1);
    CHECK(d.cloud.points[0] == taxel::Vec3d::Zero());
    CHECK_THROWS_WITH(tio::parse_ply("ply\nformat ascii 1.0\nelement marker 4000000000\n"
                                     "end_header\n\n\n"),
                      Contains("declares 4000000000 entries"));
    const auto ascii = tio::parse_ply(
        "ply\nformat ascii 1.0\nelement marker 2\nelement vertex 1\nproperty double x\n"
        "property double y\nproperty double z\nend_header\n\n\n1 2 3\n");
    REQUIRE(ascii.cloud.size() == 1);
    CHECK(ascii.cloud.points[0] == taxel::Vec3d(1, 2, 3));
  }
  CHECK_THROWS_WITH(tio::read_ply("/nonexistent/x.ply"), Contains("cannot open"));
  taxel::PointCloud<double> nan_cloud;
  nan_cloud.points.emplace_back(std::nan(""), 0.0, 0.0);
  CHECK_THROWS_AS(tio::encode_ply(nan_cloud), std::invalid_argument);
}

TEST_CASE("Contacts CSV: round trip, foreign layouts, strict errors", "[io][csv]") {
  namespace tio = taxel::io;
  std::vector<taxel::Contact<double>> contacts(3);
  contacts[0].position = {0.01, -0.02, 0.03};
  contacts[0].time = 0.001;
  contacts[0].covariance = taxel::pad_covariance<double>({0, 0, 1}, 1e-3, 9.8e-4);
  contacts[0].normal = taxel::Vec3d(0, 0, 1);
  contacts[0].pressure = 1234.5;
  contacts[0].normal_sigma = 0.0625;
  contacts[0].footprint_sigma = 9.8e-4;
  contacts[1].position = {1.0 / 3.0, 2e-9, -7.25};
  contacts[2].position = {0, 0, 0};
  contacts[2].normal = taxel::Vec3d(0.6, 0.8, 0);
  const auto back = tio::parse_contacts_csv(tio::encode_contacts_csv(contacts));
  REQUIRE(back.size() == 3);
  for (std::size_t i = 0; i < 3; ++i) {
    CHECK(back[i].position == contacts[i].position);
    CHECK(back[i].covariance == contacts[i].covariance);
    CHECK(back[i].normal == contacts[i].normal);
    CHECK(back[i].time == contacts[i].time);
    CHECK(back[i].pressure == contacts[i].pressure);
    CHECK(back[i].normal_sigma == contacts[i].normal_sigma);
    CHECK(back[i].footprint_sigma == contacts[i].footprint_sigma);
  }
  // A normal's sigma may be left empty (not stated, 0), as for a contact without a normal.
  const auto sigmas = tio::parse_contacts_csv("x,y,z,normal_sigma\n1,2,3,\n4,5,6,0.2\n");
  REQUIRE(sigmas.size() == 2);
  CHECK(sigmas[0].normal_sigma == 0.0);
  CHECK(sigmas[1].normal_sigma == 0.2);
  // So may a footprint (0: the lateral covariance is scatter).
  const auto feet = tio::parse_contacts_csv("x,y,z,footprint_sigma\n1,2,3,\n4,5,6,1e-3\n");
  REQUIRE(feet.size() == 2);
  CHECK(feet[0].footprint_sigma == 0.0);
  CHECK(feet[1].footprint_sigma == 1e-3);
  // Only positions, reordered columns, comments, CRLF, blank lines.
  const auto minimal = tio::parse_contacts_csv("# exported\r\nz, x ,y\r\n\r\n3,1,2\r\n6,4,5\r\n");
  REQUIRE(minimal.size() == 2);
  CHECK(minimal[1].position == taxel::Vec3d(4, 5, 6));
  CHECK(minimal[1].covariance == taxel::Mat3d::Identity() * 1e-6);
  CHECK_FALSE(minimal[0].normal);

  struct Bad {
    std::string text;
    const char* message;
  };
  const std::vector<Bad> bad{
      {"", "no header line"},
      {"x,y,w\n", ":1: column 3: unknown column 'w'"},
      {"x,y,z,x\n", ":1: column 4: column 'x' appears twice"},
      {"time,x,y\n", ":1: the header needs columns x, y and z"},
      {"x,y,z,cxx\n", ":1: covariance needs all six"},
      {"x,y,z,nx,ny\n", ":1: the normal needs nx, ny and nz"},
      {"x,y,z\n1,2\n", ":2: row has 2 values; the header has 3"},
      {"x,y,z\n1,2,3\n1,2,abc\n", ":3: column 3: 'abc' is not a number"},
      {"x,y,z\nnan,2,3\n", ":2: column 1: the position is not finite"},
      {"x,y,z\n1,,3\n", ":2: column 2: y is empty"},
      {"x,y,z,nx,ny,nz\n1,2,3,0,,1\n", ":2: column 4: a normal needs nx, ny and nz"},
      {"time,x,y,z\n1e999,1,2,3\n", ":2: column 1: '1e999' is not a number"},
  };
  for (const auto& [text, message] : bad) {
    INFO(text);
    CHECK_THROWS_WITH(tio::parse_contacts_csv(text), Contains(message));
  }
  CHECK_THROWS_WITH(tio::read_contacts_csv("/nonexistent.csv"), Contains("cannot open"));
  // Lenient: every bad row of the table above is skipped and counted, the first reason kept;
  // unknown columns are named and ignored; a bad header is still refused.
  for (const auto& [text, message] : bad) {
    INFO(text);
    tio::ContactsCsvReport report;
    const std::string_view t(text);
    if (t.find('\n') == std::string_view::npos || t.find('\n') == t.size() - 1) {
      if (t.find(",w") == std::string_view::npos) {
        CHECK_THROWS_WITH(tio::parse_contacts_csv(text, "<csv>", {.strict = false}, &report),
                          Contains(message));
      }
      continue;  // header-only cases
    }
    const auto kept = tio::parse_contacts_csv(text, "<csv>", {.strict = false}, &report);
    CHECK(report.skipped_rows == 1);
    CHECK_THAT(report.first_skipped, Contains(message));
    CHECK(kept.size() + 1 == static_cast<std::size_t>(std::count(t.begin(), t.end(), '\n')) - 1);
  }
  tio::ContactsCsvReport report;
  const auto kept = tio::parse_contacts_csv("finger,x,y,z,side\n1,1,2,3,left\n2,4,5,6,right\n",
                                            "<csv>", {.strict = false}, &report);
  REQUIRE(kept.size() == 2);
  CHECK(kept[1].position == taxel::Vec3d(4, 5, 6));
  CHECK(report.ignored_columns == std::vector<std::string>{"finger", "side"});
  CHECK(report.skipped_rows == 0);
}

TEST_CASE("PLY: a property named twice is refused, not silently reordered", "[io][ply]") {
  const std::string twice =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty float x\nend_header\n1 2 3 4\n";
  CHECK_THROWS_WITH(tio::parse_ply(twice, "twice.ply"),
                    Contains("twice.ply:7:") && Contains("two properties named 'x'"));
  // The same name in two elements is fine.
  const std::string two_elements =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nelement extra 1\nproperty float x\nend_header\n1 2 3\n9\n";
  CHECK(tio::parse_ply(two_elements).cloud.points.at(0).x() == 1.0);
}

namespace {
std::filesystem::path fresh_dir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}
// The message of the taxel::IoError that `write` throws while files may grow to 4 KiB at most
// (the file size limit stands in for a full disk), or "" when it throws none.
template <class Write>
std::string io_error_under_size_limit(Write write) {
  struct ::rlimit old {};
  REQUIRE(::getrlimit(RLIMIT_FSIZE, &old) == 0);
  const auto previous_handler = std::signal(SIGXFSZ, SIG_IGN);
  struct ::rlimit small = old;
  small.rlim_cur = 4096;
  REQUIRE(::setrlimit(RLIMIT_FSIZE, &small) == 0);
  std::string error;
  try {
    write();
  } catch (const taxel::IoError& e) {
    error = e.what();
  }
  ::setrlimit(RLIMIT_FSIZE, &old);
  std::signal(SIGXFSZ, previous_handler);
  return error;
}
std::size_t entries(const std::filesystem::path& dir) {
  return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir),
                                                std::filesystem::directory_iterator()));
}
}  // namespace

TEST_CASE("write_file: whole or not at all, the previous file kept on failure",
          "[io][reliability]") {
  const auto dir = fresh_dir("taxel_write_file_test");
  const std::string path = (dir / "out.txt").string();
  tio::write_file(path, "first version\n");
  CHECK(tio::read_file(path) == "first version\n");
  tio::write_file(path, "second");
  CHECK(tio::read_file(path) == "second");
  CHECK(entries(dir) == 1);  // no temporary left beside it

  // Permissions of an existing file are kept.
  ::chmod(path.c_str(), 0640);
  tio::write_file(path, "third");
  struct ::stat st {};
  REQUIRE(::stat(path.c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0640);

  // A write that fails half way (the file size limit stands in for a full disk): the error
  // names the file and the reason; the old content survives; nothing is left behind.
  const std::string error =
      io_error_under_size_limit([&] { tio::write_file(path, std::string(100000, 'x')); });
  CHECK_THAT(error, Contains("out.txt") && Contains("File too large"));
  CHECK(tio::read_file(path) == "third");
  CHECK(entries(dir) == 1);

  // A device is written in place, and its failure reported.
  CHECK_THROWS_WITH(tio::write_file("/dev/full", "x"),
                    Contains("/dev/full") && Contains("No space left"));
  tio::write_file("/dev/null", "discarded");
  // A folder, a missing folder, an empty name.
  CHECK_THROWS_WITH(tio::write_file(dir.string(), "x"), Contains("folder"));
  CHECK_THROWS_WITH(tio::write_file((dir / "missing" / "x.txt").string(), "x"),
                    Contains("missing") && Contains("No such file"));
  CHECK_THROWS_WITH(tio::write_file("", "x"), Contains("empty"));

  // A symbolic link: the file it names is replaced, the link stays a link.
  const auto link = dir / "link.txt";
  std::filesystem::create_symlink(dir / "out.txt", link);
  tio::write_file(link.string(), "through the link");
  CHECK(std::filesystem::is_symlink(link));
  CHECK(tio::read_file(path) == "through the link");
  std::filesystem::remove_all(dir);
}

TEST_CASE("read_file: folders, devices and size limits", "[io][reliability]") {
  const auto dir = fresh_dir("taxel_read_file_test");
  CHECK_THROWS_WITH(tio::read_file(dir.string()), Contains("is a folder"));
  CHECK_THROWS_WITH(tio::read_file((dir / "absent").string()), Contains("No such file"));
  CHECK(tio::read_file("/dev/null").empty());  // a device read to its end
  tio::write_file((dir / "ten").string(), "0123456789");
  CHECK_THROWS_WITH(tio::read_file((dir / "ten").string(), 9),
                    Contains("ten") && Contains("the limit is 9 bytes"));
  CHECK(tio::read_file((dir / "ten").string(), 10) == "0123456789");
  // A device that never ends stops at the limit instead of filling memory.
  CHECK_THROWS_WITH(tio::read_file("/dev/zero", 1 << 20), Contains("the limit is 1048576"));
  std::filesystem::remove_all(dir);
}

TEST_CASE("libsvm: a tiny file naming a huge feature index is refused, not expanded",
          "[io][reliability]") {
  CHECK_THROWS_WITH(
      tio::parse_libsvm("1 134217728:1\n", "huge.libsvm"),
      Contains("huge.libsvm") && Contains("134217728 features") && Contains("max_values"));
  tio::LibsvmReadOptions raised;
  raised.max_values = std::uint64_t{1} << 28;
  CHECK_THROWS_WITH(tio::parse_libsvm("1 1000000000:1\n", "huge.libsvm", raised),
                    Contains("exceed"));
}

TEST_CASE("image readers refuse images beyond the size limit with the file name",
          "[io][reliability]") {
  CHECK_THROWS_WITH(tio::parse_pgm("P5\n8192 8192\n255\n", "big.pgm"),
                    Contains("big.pgm") && Contains("limit"));
}

TEST_CASE("write_files: a set is written whole, or none of its files is replaced",
          "[io][reliability]") {
  const auto dir = fresh_dir("taxel_write_files_test");
  const std::string a = (dir / "readings.npy").string(), b = (dir / "poses.csv").string();
  tio::write_files({{a, "readings 1"}, {b, "poses 1"}});
  CHECK(tio::read_file(a) == "readings 1");
  CHECK(tio::read_file(b) == "poses 1");
  // The second file cannot be written (its folder is missing): the first keeps its old text.
  const std::string lost = (dir / "missing" / "poses.csv").string();
  CHECK_THROWS_WITH(tio::write_files({{a, "readings 2"}, {lost, "poses 2"}}),
                    Contains("missing") && Contains("No such file"));
  CHECK(tio::read_file(a) == "readings 1");
  // A file that fills the disk part-way (the size limit stands in for it): neither replaced.
  const std::string error = io_error_under_size_limit([&] {
    tio::write_files({{a, "readings 3"}, {b, std::string(100000, 'x')}});
  });
  CHECK_THAT(error, Contains("poses.csv") && Contains("File too large"));
  CHECK(tio::read_file(a) == "readings 1");
  CHECK(tio::read_file(b) == "poses 1");
  CHECK(entries(dir) == 2);  // no temporary left behind
}

TEST_CASE("LineReader and FileLineReader: LF, CRLF, a lone CR, and a byte-order mark",
          "[io][reliability]") {
  const std::string text =
      "\xEF\xBB\xBF"
      "a,b\r\nc\rd\n\ne\r";
  const std::vector<std::string> want{"a,b", "c", "d", "", "e"};
  std::vector<std::string> got;
  tio::LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) got.emplace_back(line);
  CHECK(got == want);
  CHECK(lines.line_number() == 5);

  // The same from a file, with a CRLF split across two blocks of the reader.
  const auto dir = fresh_dir("taxel_file_line_reader_test");
  const std::string path = (dir / "lines.txt").string();
  // The CR is the last byte of the first block, its LF the first of the second.
  std::string big(tio::FileLineReader::kBlockBytes - 1 - text.size(), 'x');
  big += "\r\nlast";
  tio::write_file(path, text + big);
  tio::FileLineReader file(path);
  got.clear();
  while (file.next(line)) got.emplace_back(line);
  REQUIRE(got.size() == 7);
  CHECK(std::vector<std::string>(got.begin(), got.begin() + 5) == want);
  CHECK(got[5] == big.substr(0, big.size() - 6));  // neither the CR nor the LF is part of it
  CHECK(got[6] == "last");
  CHECK_THROWS_WITH(tio::FileLineReader((dir / "none.txt").string()), Contains("cannot open"));
  CHECK_THROWS_WITH(tio::FileLineReader(dir.string()), Contains("folder"));
}

TEST_CASE("ContactsCsvReader streams what parse_contacts_csv reads, in batches",
          "[io][reliability]") {
  std::string text =
      "\xEF\xBB\xBF"
      "time,x,y,z,pressure\r";
  for (int i = 0; i < 1000; ++i) {
    text += std::to_string(i) + "," + std::to_string(i * 1e-3) + ",0,0,1\r";
  }
  const auto dir = fresh_dir("taxel_contacts_reader_test");
  const std::string path = (dir / "c.csv").string();
  tio::write_file(path, text);
  const auto whole = tio::parse_contacts_csv(text);
  REQUIRE(whole.size() == 1000);
  CHECK(whole[999].time == 999.0);  // the time column is read despite the mark
  tio::ContactsCsvReader reader(path);
  std::vector<taxel::Contact<double>> all, batch;
  bool more = true;
  while (more) {
    batch.clear();
    more = reader.read(batch, 64);
    CHECK(batch.size() <= 64);
    all.insert(all.end(), batch.begin(), batch.end());
  }
  REQUIRE(all.size() == whole.size());
  for (std::size_t i = 0; i < all.size(); ++i) {
    CHECK(all[i].position == whole[i].position);
    CHECK(all[i].time == whole[i].time);
  }
  // NaN time or pressure: a bad row, with its line and column.
  CHECK_THROWS_WITH(tio::parse_contacts_csv("time,x,y,z\nnan,0,0,0\n"),
                    Contains("<csv>:2: column 1: time is not finite"));
  CHECK_THROWS_WITH(tio::parse_contacts_csv("x,y,z,pressure\n0,0,0,inf\n"),
                    Contains("<csv>:2: column 4: pressure is not finite"));
}

TEST_CASE("IoError shows control bytes of its input instead of ending the message there",
          "[io][reliability]") {
  const taxel::IoError e("f.csv", std::string("bad cell 'a\0b\nc'", 16), 3);
  CHECK(std::string(e.what()) == "f.csv:3: bad cell 'a\\x00b\\x0ac'");
}

TEST_CASE("npy shapes follow Python's tuple grammar", "[io][reliability]") {
  const std::string one(2, '\0');
  CHECK(tio::parse_npy_u16(npy("<u2", "(1,)", one)).shape == std::vector<std::size_t>{1});
  CHECK(tio::parse_npy_u16(npy("<u2", "(1, 1,)", one)).shape == std::vector<std::size_t>{1, 1});
  for (const char* bad : {"(1,, 1)", "(,)", "(1, ,)", "(,1)"}) {
    CAPTURE(bad);
    CHECK_THROWS_WITH(tio::parse_npy_u16(npy("<u2", bad, one)),
                      Contains("is not a tuple of sizes"));
  }
}

TEST_CASE("io: float64 and uint8 arrays are written as numpy writes them and read back", "[io]") {
  const std::size_t shape[] = {2, 3};
  const std::vector<double> v = {0.0, -1.5, 1e-300, 3.25, std::numeric_limits<double>::max(), -0.0};
  const std::string f = tio::encode_npy_f64(shape, v);
  // numpy's header for this array, padded to 64 bytes (NEP 1).
  CHECK(f.substr(0, 8) == std::string("\x93NUMPY\x01\x00", 8));
  CHECK(f.find("{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }") == 10);
  const tio::NpyArray a = tio::parse_npy_header(f, "<f8>", 100);
  REQUIRE(a.count == 6);
  CHECK(a.data_at % 64 == 0);
  for (std::size_t i = 0; i < v.size(); ++i) CHECK(a.value(f, i) == v[i]);
  const std::uint8_t bytes[] = {0, 1, 254, 255, 7, 9};
  const std::string u = tio::encode_npy_u8(shape, bytes);
  CHECK(u.find("'descr': '|u1'") != std::string::npos);
  const tio::NpyArray b = tio::parse_npy_header(u, "<u1>", 100);
  for (std::size_t i = 0; i < 6; ++i) CHECK(b.value(u, i) == bytes[i]);
  CHECK_THROWS_WITH(tio::encode_npy_f64(shape, std::vector<double>(5)),
                    Catch::Contains("shape holds 6 values, got 5"));
}

#if defined(TAXEL_TEST_HAVE_JPEG)
namespace {
// A JPEG encoded by libjpeg itself (quality 95, 4:4:4), independent of the reader under test.
std::string encode_jpeg(const tio::RgbImage& img, bool grey = false) {
  jpeg_compress_struct info{};
  jpeg_error_mgr err{};
  info.err = jpeg_std_error(&err);
  jpeg_create_compress(&info);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&info, &out, &size);
  info.image_width = static_cast<JDIMENSION>(img.cols);
  info.image_height = static_cast<JDIMENSION>(img.rows);
  info.input_components = grey ? 1 : 3;
  info.in_color_space = grey ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&info);
  jpeg_set_quality(&info, 95, TRUE);
  for (int c = 0; c < info.num_components; ++c) {
    info.comp_info[c].h_samp_factor = 1;
    info.comp_info[c].v_samp_factor = 1;
  }
  jpeg_start_compress(&info, TRUE);
  std::vector<unsigned char> row(static_cast<std::size_t>(img.cols) * 3);
  while (info.next_scanline < info.image_height) {
    const auto r = static_cast<Eigen::Index>(info.next_scanline);
    for (Eigen::Index c = 0; c < img.cols; ++c) {
      const std::uint8_t* p = img.data.data() + (r * img.cols + c) * 3;
      if (grey) {
        row[static_cast<std::size_t>(c)] = p[0];
      } else {
        std::copy_n(p, 3, row.data() + c * 3);
      }
    }
    JSAMPROW ptr = row.data();
    jpeg_write_scanlines(&info, &ptr, 1);
  }
  jpeg_finish_compress(&info);
  jpeg_destroy_compress(&info);
  std::string bytes(reinterpret_cast<const char*>(out), size);
  std::free(out);
  return bytes;
}
}  // namespace

TEST_CASE("io: JPEG frames are read, and truncated or foreign files refused", "[io]") {
  // A smooth colour ramp, which JPEG keeps within a few levels.
  tio::RgbImage img(48, 64, 0);
  for (Eigen::Index r = 0; r < img.rows; ++r) {
    for (Eigen::Index c = 0; c < img.cols; ++c) {
      std::uint8_t* p = img.at(r, c);
      p[0] = static_cast<std::uint8_t>(40 + 2 * c);
      p[1] = static_cast<std::uint8_t>(60 + 3 * r);
      p[2] = static_cast<std::uint8_t>(120 + r + c);
    }
  }
  const std::string bytes = encode_jpeg(img);
  const tio::RgbImage back = tio::decode_jpeg(bytes, "ramp.jpg");
  REQUIRE(back.rows == 48);
  REQUIRE(back.cols == 64);
  int worst = 0;
  for (std::size_t i = 0; i < img.data.size(); ++i) {
    worst = std::max(worst, std::abs(int(back.data[i]) - int(img.data[i])));
  }
  CHECK(worst <= 4);
  // Greyscale is expanded to three equal channels.
  const tio::RgbImage grey = tio::decode_jpeg(encode_jpeg(img, true), "grey.jpg");
  REQUIRE(grey.rows == 48);
  CHECK(grey.data[0] == grey.data[1]);
  CHECK(grey.data[1] == grey.data[2]);
  // From a file.
  const auto dir = std::filesystem::temp_directory_path() / "taxel_jpeg_test";
  std::filesystem::create_directories(dir);
  tio::write_file((dir / "ramp.jpg").string(), bytes);
  CHECK(tio::read_jpeg((dir / "ramp.jpg").string()).data == back.data);
  // Cut anywhere after the header: an error, never a frame filled with grey.
  for (const std::size_t cut :
       {std::size_t{2}, std::size_t{200}, bytes.size() / 2, bytes.size() - 2}) {
    CAPTURE(cut);
    CHECK_THROWS_AS(tio::decode_jpeg(bytes.substr(0, cut), "cut.jpg"), taxel::IoError);
  }
  CHECK_THROWS_WITH(tio::decode_jpeg(bytes.substr(0, bytes.size() / 2), "cut.jpg"),
                    Catch::Contains("cut.jpg") && Catch::Contains("JPEG read failed"));
  CHECK_THROWS_WITH(tio::decode_jpeg("\x89PNG\r\n", "x.png"), Catch::Contains("not a JPEG"));
  CHECK_THROWS_WITH(
      tio::decode_jpeg(std::string("\xFF\xD8\xFF") + std::string(100, 'x'), "bad.jpg"),
      Catch::Contains("JPEG read failed"));
  CHECK_THROWS_AS(tio::read_jpeg((dir / "missing.jpg").string()), taxel::IoError);
  std::filesystem::remove_all(dir);
}
#endif
