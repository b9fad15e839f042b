// SPDX-License-Identifier: MIT
// Pad poses per frame as CSV: where each tactile pad was (from the hand's forward kinematics)
// when a frame of readings was taken. One row per frame and pad; a header names the columns:
//   frame,pad,x,y,z,qw,qx,qy,qz[,time]
// frame: 0-based index into the stack of readings; pad: 0-based pad index within the frame;
// x, y, z: the pad origin in the world [m]; qw..qz: the unit quaternion of the pad -> world
// rotation (pad frame as in sensor/pad.hpp: tactel rows along y, sensing face along +z);
// time: seconds (optional). The drivers' pose files (columns time_ms and matrix instead of
// frame and pad) are read too: their frames are numbered by distinct time_ms in order of first
// appearance, and time is time_ms / 1000.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/core/types.hpp"
#include "taxel/io/file.hpp"

namespace taxel::io {

/// One pad's pose in one frame.
struct PadPose {
  std::size_t frame = 0;  ///< index of the frame in the stack of readings
  std::size_t pad = 0;    ///< index of the pad within the frame
  double time = std::numeric_limits<double>::quiet_NaN();  ///< [s]; NaN when the file has none
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< pad -> world
};

/// Parses pad poses (see the file comment). Throws IoError naming `source`, the line and the
/// problem: a missing column, a cell that is not a finite number, a negative or fractional
/// index, a quaternion whose norm differs from 1 by more than 1e-3 (it is normalised
/// otherwise), or the same frame and pad twice.
template <class = void>
inline std::vector<PadPose> parse_pad_poses_csv(std::string_view text,
                                                const std::string& source = "<poses>") {
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line) && blank_or_comment(line)) {
  }
  if (lines.line_number() == 0 || blank_or_comment(line)) {
    throw IoError(source, "empty: expected a header such as frame,pad,x,y,z,qw,qx,qy,qz");
  }
  // Calls cell(k, text) for the comma-separated, blank-trimmed cells of a line, k from 0.
  const auto split = [](std::string_view row, const auto& cell) {
    std::size_t k = 0, start = 0;
    for (;;) {
      const std::size_t comma = row.find(',', start);
      std::string_view c = row.substr(start, comma - start);
      while (!c.empty() && c.front() == ' ') c.remove_prefix(1);
      while (!c.empty() && c.back() == ' ') c.remove_suffix(1);
      cell(k++, c);
      if (comma == std::string_view::npos) return k;
      start = comma + 1;
    }
  };
  std::map<std::string, std::size_t, std::less<>> column;
  split(line, [&](std::size_t k, std::string_view name) {
    if (!column.emplace(std::string(name), k).second) {
      throw IoError(source, "column '" + std::string(name) + "' appears twice", 1);
    }
  });
  const auto find = [&](std::string_view a, std::string_view b) -> std::ptrdiff_t {
    if (auto it = column.find(a); it != column.end()) return std::ptrdiff_t(it->second);
    if (auto it = column.find(b); !b.empty() && it != column.end())
      return std::ptrdiff_t(it->second);
    return -1;
  };
  const bool by_time = column.count("frame") == 0 && column.count("time_ms") == 1;
  const std::ptrdiff_t c_frame = find("frame", "time_ms"), c_pad = find("pad", "matrix");
  const std::ptrdiff_t c_time = find("time", "");
  std::ptrdiff_t c_val[7];
  const char* names[7] = {"x", "y", "z", "qw", "qx", "qy", "qz"};
  for (int k = 0; k < 7; ++k) c_val[k] = find(names[k], "");
  if (c_frame < 0 || c_pad < 0 || std::find(c_val, c_val + 7, -1) != c_val + 7) {
    throw IoError(source,
                  "the header needs the columns frame (or time_ms), pad (or matrix), x, y, z, "
                  "qw, qx, qy, qz",
                  1);
  }
  const std::size_t width = column.size();
  std::vector<PadPose> out;
  std::set<std::pair<std::size_t, std::size_t>> seen;
  std::map<double, std::size_t> frame_of_time;  // drivers' files: time_ms -> frame
  std::vector<double> cells(width);
  while (lines.next(line)) {
    if (blank_or_comment(line)) continue;
    const auto n = lines.line_number();
    const std::size_t k = split(line, [&](std::size_t i, std::string_view cell) {
      if (i >= width) throw IoError(source, "more cells than header columns", n);
      double v = 0.0;
      const auto r = std::from_chars(cell.data(), cell.data() + cell.size(), v);
      if (r.ec != std::errc() || r.ptr != cell.data() + cell.size() || !std::isfinite(v)) {
        throw IoError(source,
                      "column " + std::to_string(i + 1) + ": '" + std::string(cell) +
                          "' is not a finite number",
                      n);
      }
      cells[i] = v;
    });
    if (k != width) {
      throw IoError(source, std::to_string(k) + " cells, the header has " + std::to_string(width),
                    n);
    }
    const auto index = [&](std::ptrdiff_t c, const char* what) {
      const double v = cells[std::size_t(c)];
      if (!(v >= 0) || v != std::floor(v) || v > 4294967295.0) {
        throw IoError(source, std::string(what) + " must be a whole number in [0, 2^32)", n);
      }
      return v;
    };
    PadPose p;
    const double key = index(c_frame, by_time ? "time_ms" : "frame");
    if (by_time) {
      p.frame = frame_of_time.emplace(key, frame_of_time.size()).first->second;
      p.time = key * 1e-3;
    } else {
      p.frame = static_cast<std::size_t>(key);
    }
    p.pad = static_cast<std::size_t>(index(c_pad, by_time ? "matrix" : "pad"));
    if (c_time >= 0) p.time = cells[std::size_t(c_time)];
    Eigen::Quaterniond q(cells[std::size_t(c_val[3])], cells[std::size_t(c_val[4])],
                         cells[std::size_t(c_val[5])], cells[std::size_t(c_val[6])]);
    if (!(std::abs(q.norm() - 1.0) <= 1e-3)) {
      throw IoError(
          source,
          "the quaternion (qw, qx, qy, qz) has norm " + std::to_string(q.norm()) + ", expected 1",
          n);
    }
    q.normalize();
    p.pose.linear() = q.toRotationMatrix();
    p.pose.translation() = Vec3d(cells[std::size_t(c_val[0])], cells[std::size_t(c_val[1])],
                                 cells[std::size_t(c_val[2])]);
    if (!seen.emplace(p.frame, p.pad).second) {
      throw IoError(source,
                    "frame " + std::to_string(p.frame) + ", pad " + std::to_string(p.pad) +
                        " has a pose already",
                    n);
    }
    out.push_back(p);
  }
  return out;
}

/// Reads a pad poses file (see parse_pad_poses_csv).
template <class = void>
inline std::vector<PadPose> read_pad_poses_csv(const std::string& path) {
  return parse_pad_poses_csv(read_file(path), path);
}

/// The CSV text of `poses` (header frame,pad,x,y,z,qw,qx,qy,qz and, when every pose has a
/// finite time, time; shortest round-trip decimal form).
template <class = void>
inline std::string encode_pad_poses_csv(std::span<const PadPose> poses) {
  const bool timed = std::all_of(poses.begin(), poses.end(),
                                 [](const PadPose& p) { return std::isfinite(p.time); });
  std::string out = timed ? "frame,pad,x,y,z,qw,qx,qy,qz,time\n" : "frame,pad,x,y,z,qw,qx,qy,qz\n";
  char buf[64];
  const auto num = [&](double v) {
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
  };
  for (const PadPose& p : poses) {
    const Eigen::Quaterniond q(p.pose.linear());
    out += std::to_string(p.frame) + "," + std::to_string(p.pad);
    for (const double v : {p.pose.translation().x(), p.pose.translation().y(),
                           p.pose.translation().z(), q.w(), q.x(), q.y(), q.z()}) {
      out.push_back(',');
      num(v);
    }
    if (timed) {
      out.push_back(',');
      num(p.time);
    }
    out.push_back('\n');
  }
  return out;
}

}  // namespace taxel::io
