// SPDX-License-Identifier: MIT
// 05_segment_and_describe: one pressure image through the second paper's chain. Segments it
// into background / low / high pressure, describes the high-pressure regions, decides edged or
// edgeless, reconstructs the height map, and writes a picture of the four stages.
//   05_segment_and_describe [--out DIR] [IMAGE]
// Without IMAGE it makes a 32x32 palm grasp of a cuboid (two parallel pressure ridges).
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>
#include <string_view>
#include <taxel/image.hpp>
#include <taxel/io.hpp>
#if defined(TAXEL_EXAMPLES_HAVE_PNG)
#include <taxel/io/png.hpp>
#endif

namespace {

namespace ti = taxel::image;

// A palm (rows 5-28) with four fingers (rows 0-4, gaps between them), pressing on a cuboid whose
// two edges run across the palm as high-pressure ridges.
ti::ImageD cuboid_grasp() {
  ti::ImageD img = ti::ImageD::Zero(32, 32);
  for (int r = 0; r < 29; ++r) {
    for (int c = 4; c < 28; ++c) {
      const bool finger_gap = r < 5 && (c % 6 == 3 || c % 6 == 4);
      if (finger_gap) continue;
      const double ridge = std::exp(-0.5 * std::pow((r - 10.0) / 1.2, 2)) +
                           std::exp(-0.5 * std::pow((r - 21.0) / 1.2, 2));
      img(r, c) = std::round(std::min(255.0, 70.0 + 12.0 * std::sin(0.4 * c) + 160.0 * ridge));
    }
  }
  return img;
}

}  // namespace

int main(int argc, char** argv) try {
  std::filesystem::path out_dir = "05-output";
  std::string input;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "-h" || a == "--help") {
      std::puts("usage: 05_segment_and_describe [--out DIR] [IMAGE.csv|.pgm|.npy]");
      return 0;
    }
    if (a == "--out" && i + 1 < argc) {
      out_dir = argv[++i];
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "05_segment_and_describe: unknown option '%s'\n", argv[i]);
      return 2;
    } else {
      input = argv[i];
    }
  }
  const ti::ImageD img =
      input.empty() ? cuboid_grasp() : ti::ImageD(taxel::io::read_image(input).frame(0));

  ti::Recognizer<> rec(img.rows(), img.cols());
  const ti::Recognition& r = rec.recognize(img);
  if (!r.ok()) {
    std::fprintf(stderr, "05_segment_and_describe: %s\n", r.message.c_str());
    return 1;
  }
  const ti::Segmentation& seg = rec.segmentation();
  const ti::RegionProps props = ti::region_props(seg.high);
  std::printf("image %lldx%lld, k-means centroids:", static_cast<long long>(img.rows()),
              static_cast<long long>(img.cols()));
  for (double c : seg.kmeans.centroids) std::printf(" %.1f", c);
  std::printf("\nhigh-pressure regions: %d, area %.0f px\n", seg.regions, props.area);
  std::printf("centroid (%.2f, %.2f), bounding box [%.1f %.1f %.0f %.0f]\n", props.centroid.x(),
              props.centroid.y(), props.bounding_box(0), props.bounding_box(1),
              props.bounding_box(2), props.bounding_box(3));
  std::printf("convex area %.0f, solidity %.3f, eccentricity %.3f, orientation %.2f deg\n",
              props.convex_area, props.solidity, props.eccentricity, props.orientation);
  std::printf("Euler number %d, perimeter %.2f\n", props.euler_number, props.perimeter);
  std::printf("contour gradient Gm = %.1f -> %s (threshold 25) -> %s\n", r.contour_gradient,
              r.edged ? "edged" : "edgeless", r.edged ? "RecEdged" : "RecEdgeless");

  // Picture: image | classes | HPRs | reconstruction, each pixel 8x8.
  ti::Image<std::uint8_t> hpr = seg.high;
  const double hmax = std::max(1e-9, rec.reconstruction().maxCoeff());
  const auto picture = taxel::io::side_by_side(
      {taxel::io::colorize(img, 0, 255), taxel::io::colorize_classes(seg.classes),
       taxel::io::colorize_classes(hpr * std::uint8_t{2}),
       taxel::io::colorize(rec.reconstruction(), 0, hmax)});
  std::filesystem::create_directories(out_dir);
#if defined(TAXEL_EXAMPLES_HAVE_PNG)
  const auto file = out_dir / "segment_and_describe.png";
  taxel::io::write_png(file.string(), picture);
#else
  const auto file = out_dir / "segment_and_describe.ppm";
  taxel::io::write_file(file.string(), taxel::io::encode_ppm(picture));
#endif
  std::printf("wrote %s (image | segmentation | HPRs | reconstruction)\n", file.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "05_segment_and_describe: %s\n", e.what());
  return 1;
}
