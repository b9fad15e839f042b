// SPDX-License-Identifier: MIT
// Fuzzes the PLY reader with arbitrary bytes after a valid-looking magic line (the first byte
// picks ASCII, binary or free-form). It must throw taxel::IoError or return a consistent cloud:
// finite points, normals and fields sized to the points, triangle indices in range; what reads
// must encode and read back to the same points.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <taxel/io/ply.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static const char* kHeads[] = {"ply\nformat ascii 1.0\n",
                                 "ply\nformat binary_little_endian 1.0\n", ""};
  std::string bytes = kHeads[data[0] % 3];
  bytes.append(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    const taxel::io::PlyData d = taxel::io::parse_ply(bytes, "<fuzz>");
    if (!d.cloud.validate().ok()) std::abort();
    for (const auto& t : d.triangles) {
      for (const auto i : t) {
        if (i >= d.cloud.size()) std::abort();
      }
    }
    const taxel::io::PlyData back = taxel::io::parse_ply(
        taxel::io::encode_ply(d.cloud, taxel::io::PlyFormat::binary_little_endian, d.triangles));
    if (back.cloud.points != d.cloud.points || back.triangles != d.triangles) std::abort();
  } catch (const taxel::IoError&) {
  } catch (const std::invalid_argument&) {  // a field name with spaces cannot be re-encoded
  }
  return 0;
}
