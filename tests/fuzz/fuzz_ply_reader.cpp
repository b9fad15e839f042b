// SPDX-License-Identifier: MIT
// Fuzzes the PLY reader with arbitrary bytes after a valid-looking magic line (the first byte
// picks ASCII, binary or free-form). It must throw taxel::IoError or return a consistent cloud:
// finite points, normals and fields sized to the points, triangle indices in range; what reads
// must encode and read back to the same points, normals and fields.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
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
    // Normals and every named field come back in place too (a property named twice once
    // swapped values on this round trip). NaN fields compare unequal, so compare bits.
    if (back.cloud.normals != d.cloud.normals ||
        back.cloud.fields.size() != d.cloud.fields.size()) {
      std::abort();
    }
    for (std::size_t f = 0; f < d.cloud.fields.size(); ++f) {
      const auto& x = d.cloud.fields[f];
      const auto& y = back.cloud.fields[f];
      if (x.name != y.name || x.values.size() != y.values.size() ||
          std::memcmp(x.values.data(), y.values.data(), x.values.size() * sizeof(x.values[0])) !=
              0) {
        std::abort();
      }
    }
  } catch (const taxel::IoError&) {
  } catch (const std::invalid_argument&) {  // a field name with spaces cannot be re-encoded
  }
  return 0;
}
