// SPDX-License-Identifier: MIT
// Fuzzes the readings inputs: the .npy reader of reading stacks and the pad poses CSV reader,
// on arbitrary bytes (the first byte picks the reader; for .npy, also a valid v1 header of a
// small u2 stack followed by the fuzzer's bytes). Each must throw taxel::IoError or return
// values that encode and read back identically; an accepted stack with poses for every pad
// goes through contacts_from_readings, which may only throw std::invalid_argument.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <taxel/io/npy.hpp>
#include <taxel/io/pad_poses_csv.hpp>
#include <taxel/sensor/readings.hpp>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string rest(reinterpret_cast<const char*>(data + 1), size - 1);
  try {
    switch (data[0] % 3) {
      case 0:
      case 1: {
        std::string bytes = rest;
        if (data[0] % 3 == 1) {
          const std::size_t shape[4] = {1, 1, 2, 2};
          const std::uint16_t zeros[4] = {0, 0, 0, 0};
          bytes = taxel::io::encode_npy_u16(shape, zeros).substr(0, 128) + rest;
        }
        const auto a = taxel::io::parse_npy_u16(bytes, "<fuzz>");
        const auto b = taxel::io::parse_npy_u16(taxel::io::encode_npy_u16(a.shape, a.values));
        if (b.shape != a.shape || b.values != a.values) std::abort();
        if (a.shape.size() == 4 && a.values.size() <= 4096 && a.shape[2] <= 64 &&
            a.shape[3] <= 64 && a.shape[2] > 0 && a.shape[3] > 0) {
          const auto stack = taxel::sensor::ReadingStack::from_npy(a);
          std::vector<taxel::io::PadPose> poses;
          for (std::size_t f = 0; f < stack.frames; ++f)
            for (std::size_t p = 0; p < stack.pads; ++p) {
              poses.push_back({f, p, 0.0, Eigen::Isometry3d::Identity()});
            }
          taxel::sensor::SensorModel m;
          m.geometry.rows = static_cast<int>(stack.rows);
          m.geometry.cols = static_cast<int>(stack.cols);
          m.levels = 65536;
          std::vector<taxel::Contact<double>> out;
          try {
            (void)taxel::sensor::contacts_from_readings(stack, poses, m, {}, 1000.0, out);
          } catch (const std::invalid_argument&) {
          }
          for (const auto& c : out) {
            if (!c.position.allFinite() || !c.covariance.allFinite()) std::abort();
          }
        }
        break;
      }
      default: {
        const auto poses = taxel::io::parse_pad_poses_csv(rest, "<fuzz>");
        const auto back = taxel::io::parse_pad_poses_csv(taxel::io::encode_pad_poses_csv(poses));
        if (back.size() != poses.size()) std::abort();
        for (std::size_t i = 0; i < poses.size(); ++i) {
          if (back[i].frame != poses[i].frame || back[i].pad != poses[i].pad ||
              !(back[i].pose.matrix() - poses[i].pose.matrix()).isZero(1e-12)) {
            std::abort();
          }
        }
      }
    }
  } catch (const taxel::IoError&) {
  }
  return 0;
}
