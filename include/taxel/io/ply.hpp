// SPDX-License-Identifier: MIT
// PLY point clouds and triangle meshes (Stanford polygon format): ASCII and binary
// little-endian, read and write. The vertex element's x, y, z become points; nx, ny, nz
// normals; every other scalar vertex property a named field (e.g. "observations",
// "covariance_trace"). A face element with a list property (vertex_indices or vertex_index)
// becomes triangles (polygons fan-triangulated). Other elements are skipped. The reader is
// strict: any error names the line (ASCII header or body) or the byte (binary body).
#pragma once

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <unordered_set>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/core/point_cloud.hpp"
#include "taxel/io/file.hpp"

namespace taxel::io {

/// A PLY file's content.
struct PlyData {
  PointCloud<double> cloud;                             ///< points, normals, fields
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< vertex indices
};

/// Encoding of a written PLY file.
enum class PlyFormat { ascii, binary_little_endian };

namespace detail {

enum class PlyType { i8, u8, i16, u16, i32, u32, f32, f64 };

inline bool ply_type(std::string_view name, PlyType& t) {
  struct Entry {
    std::string_view name;
    PlyType type;
  };
  static constexpr Entry kTypes[] = {
      {"char", PlyType::i8},    {"int8", PlyType::i8},     {"uchar", PlyType::u8},
      {"uint8", PlyType::u8},   {"short", PlyType::i16},   {"int16", PlyType::i16},
      {"ushort", PlyType::u16}, {"uint16", PlyType::u16},  {"int", PlyType::i32},
      {"int32", PlyType::i32},  {"uint", PlyType::u32},    {"uint32", PlyType::u32},
      {"float", PlyType::f32},  {"float32", PlyType::f32}, {"double", PlyType::f64},
      {"float64", PlyType::f64}};
  for (const auto& e : kTypes) {
    if (e.name == name) {
      t = e.type;
      return true;
    }
  }
  return false;
}

inline std::size_t ply_size(PlyType t) {
  switch (t) {
    case PlyType::i8:
    case PlyType::u8:
      return 1;
    case PlyType::i16:
    case PlyType::u16:
      return 2;
    case PlyType::i32:
    case PlyType::u32:
    case PlyType::f32:
      return 4;
    case PlyType::f64:
      return 8;
  }
  return 0;
}

inline bool ply_integer(PlyType t) { return t != PlyType::f32 && t != PlyType::f64; }

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::f32;
  bool list = false;
  PlyType count_type = PlyType::u8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
};

// Reads one little-endian value at `p` (bounds already checked).
inline double ply_load(const char* p, PlyType t) {
  std::uint64_t bits = 0;
  const std::size_t n = ply_size(t);
  for (std::size_t i = 0; i < n; ++i) {
    bits |= static_cast<std::uint64_t>(static_cast<unsigned char>(p[i])) << (8 * i);
  }
  switch (t) {
    case PlyType::i8:
      return static_cast<std::int8_t>(bits);
    case PlyType::u8:
      return static_cast<double>(bits);
    case PlyType::i16:
      return static_cast<std::int16_t>(bits);
    case PlyType::u16:
      return static_cast<double>(bits);
    case PlyType::i32:
      return static_cast<std::int32_t>(bits);
    case PlyType::u32:
      return static_cast<double>(bits);
    case PlyType::f32:
      return std::bit_cast<float>(static_cast<std::uint32_t>(bits));
    case PlyType::f64:
      return std::bit_cast<double>(bits);
  }
  return 0.0;
}

// A cursor over the body that reads values either as ASCII tokens or binary.
class PlyBody {
 public:
  PlyBody(std::string_view bytes, std::size_t start, std::uint64_t line, bool binary,
          const std::string& source)
      : bytes_(bytes), pos_(start), line_(line), binary_(binary), source_(source) {}

  double value(PlyType t, const char* what) {
    if (binary_) {
      const std::size_t n = ply_size(t);
      if (bytes_.size() - pos_ < n) {
        throw IoError(source_, std::string("file ends inside ") + what, std::nullopt, pos_);
      }
      const double v = ply_load(bytes_.data() + pos_, t);
      pos_ += n;
      return v;
    }
    // ASCII: values are separated by spaces and tabs; a line holds one element.
    while (pos_ < bytes_.size() && (bytes_[pos_] == ' ' || bytes_[pos_] == '\t')) ++pos_;
    if (pos_ >= bytes_.size() || bytes_[pos_] == '\n' || bytes_[pos_] == '\r') {
      throw IoError(source_, std::string("line ends before ") + what, line_);
    }
    std::size_t end = pos_;
    while (end < bytes_.size() && bytes_[end] != ' ' && bytes_[end] != '\t' &&
           bytes_[end] != '\n' && bytes_[end] != '\r') {
      ++end;
    }
    const std::string_view tok = bytes_.substr(pos_, end - pos_);
    double v = 0.0;
    const auto res = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (res.ec != std::errc() || res.ptr != tok.data() + tok.size()) {
      throw IoError(source_,
                    "'" + std::string(tok.substr(0, 24)) + "' is not a number (" + what + ")",
                    line_);
    }
    if (ply_integer(t) && v != std::floor(v)) {
      throw IoError(source_,
                    "'" + std::string(tok.substr(0, 24)) + "' is not an integer (" + what + ")",
                    line_);
    }
    pos_ = end;
    return v;
  }

  // ASCII: the element's line must end here.
  void end_element() {
    if (binary_) return;
    while (pos_ < bytes_.size() &&
           (bytes_[pos_] == ' ' || bytes_[pos_] == '\t' || bytes_[pos_] == '\r')) {
      ++pos_;
    }
    if (pos_ < bytes_.size() && bytes_[pos_] != '\n') {
      throw IoError(source_, "more values than the header declares", line_);
    }
    if (pos_ < bytes_.size()) ++pos_;
    ++line_;
  }

  [[nodiscard]] std::size_t remaining() const noexcept { return bytes_.size() - pos_; }
  [[nodiscard]] std::size_t position() const noexcept { return pos_; }
  [[nodiscard]] std::uint64_t line() const noexcept { return line_; }

 private:
  std::string_view bytes_;
  std::size_t pos_;
  std::uint64_t line_;
  bool binary_;
  const std::string& source_;
};

}  // namespace detail

/// Parses a PLY file held in memory. Throws IoError with the line or byte of the first error:
/// a bad magic or format, big-endian data, unknown types, missing x/y/z, counts the file cannot
/// hold, truncation, malformed or non-finite numbers, face indices out of range, trailing data.
template <class = void>
inline PlyData parse_ply(std::string_view bytes, const std::string& source = "<ply>") {
  using namespace detail;
  LineReader header(bytes);
  std::uint64_t line = 0;
  const auto next_line = [&](std::string_view& out) {
    if (!header.next(out)) throw IoError(source, "the header has no end_header line", line + 1);
    line = header.line_number();
  };
  const auto words = [](std::string_view s) {
    std::vector<std::string_view> w;
    std::size_t i = 0;
    while (i < s.size()) {
      while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
      const std::size_t start = i;
      while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
      if (i > start) w.push_back(s.substr(start, i - start));
    }
    return w;
  };

  std::string_view l;
  next_line(l);
  if (l != "ply") throw IoError(source, "not a PLY file (the first line must be 'ply')", 1);
  bool binary = false;
  bool have_format = false;
  std::vector<PlyElement> elements;
  std::unordered_set<std::string> property_names;  // of the current element
  for (;;) {
    next_line(l);
    const auto w = words(l);
    if (w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") break;
    if (w[0] == "format") {
      if (w.size() != 3 || w[2] != "1.0") throw IoError(source, "malformed format line", line);
      if (w[1] == "ascii") {
        binary = false;
      } else if (w[1] == "binary_little_endian") {
        binary = true;
      } else if (w[1] == "binary_big_endian") {
        throw IoError(source, "binary_big_endian PLY is not supported (convert to little-endian)",
                      line);
      } else {
        throw IoError(source, "unknown format '" + std::string(w[1].substr(0, 24)) + "'", line);
      }
      have_format = true;
    } else if (w[0] == "element") {
      std::uint64_t n = 0;
      if (w.size() != 3 || std::from_chars(w[2].data(), w[2].data() + w[2].size(), n).ptr !=
                               w[2].data() + w[2].size()) {
        throw IoError(source, "malformed element line", line);
      }
      elements.push_back({std::string(w[1]), n, {}});
      property_names.clear();
    } else if (w[0] == "property") {
      if (elements.empty()) throw IoError(source, "property before any element", line);
      PlyProperty p;
      if (w.size() == 5 && w[1] == "list") {
        if (!ply_type(w[2], p.count_type) || !ply_type(w[3], p.type) ||
            !ply_integer(p.count_type)) {
          throw IoError(source, "bad list property types", line);
        }
        p.list = true;
        p.name = std::string(w[4]);
      } else if (w.size() == 3) {
        if (!ply_type(w[1], p.type)) {
          throw IoError(source, "unknown property type '" + std::string(w[1].substr(0, 24)) + "'",
                        line);
        }
        p.name = std::string(w[2]);
      } else {
        throw IoError(source, "malformed property line", line);
      }
      if (!property_names.insert(p.name).second) {
        throw IoError(source,
                      "element '" + elements.back().name.substr(0, 24) +
                          "' has two properties named '" + p.name.substr(0, 24) + "'",
                      line);
      }
      elements.back().properties.push_back(std::move(p));
    } else {
      throw IoError(source, "unknown header keyword '" + std::string(w[0].substr(0, 24)) + "'",
                    line);
    }
  }
  if (!have_format) throw IoError(source, "the header has no format line", line);

  PlyData out;
  PlyBody body(bytes, header.offset(), line + 1, binary, source);
  bool seen_vertex = false;
  for (const PlyElement& e : elements) {
    // Every value takes at least one byte (or its size in binary): refuse counts the
    // rest of the file cannot hold before allocating for them.
    std::size_t min_bytes = 0;
    for (const auto& p : e.properties)
      min_bytes += binary ? (p.list ? ply_size(p.count_type) : ply_size(p.type)) : 1;
    // An element without properties is empty in binary (skipped at once); in ASCII each
    // entry is still a line, the last one possibly unterminated.
    if (e.properties.empty()) {
      if (binary && e.name != "vertex") continue;
      if (e.count > body.remaining() + 1) min_bytes = 1;
    }
    if (min_bytes > 0 && e.count > body.remaining() / min_bytes) {
      throw IoError(source,
                    "element '" + e.name + "' declares " + std::to_string(e.count) +
                        " entries; the file is too short for them",
                    std::nullopt, body.position());
    }
    if (e.name == "vertex") {
      if (seen_vertex)
        throw IoError(source, "a second vertex element", std::nullopt, body.position());
      seen_vertex = true;
      int xyz[3] = {-1, -1, -1}, nxyz[3] = {-1, -1, -1};
      std::vector<int> field_of(e.properties.size(), -1);
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const auto& p = e.properties[i];
        if (p.list) continue;
        const std::string_view n = p.name;
        for (int a = 0; a < 3; ++a) {
          if (n == std::string_view(&"xyz"[a], 1)) xyz[a] = static_cast<int>(i);
          if (n.size() == 2 && n[0] == 'n' && n[1] == "xyz"[a]) nxyz[a] = static_cast<int>(i);
        }
      }
      if (xyz[0] < 0 || xyz[1] < 0 || xyz[2] < 0) {
        throw IoError(source, "the vertex element has no x, y and z properties");
      }
      const bool normals = nxyz[0] >= 0 && nxyz[1] >= 0 && nxyz[2] >= 0;
      for (std::size_t i = 0; i < e.properties.size(); ++i) {
        const auto& p = e.properties[i];
        const bool used =
            static_cast<int>(i) == xyz[0] || static_cast<int>(i) == xyz[1] ||
            static_cast<int>(i) == xyz[2] ||
            (normals && (static_cast<int>(i) == nxyz[0] || static_cast<int>(i) == nxyz[1] ||
                         static_cast<int>(i) == nxyz[2]));
        if (!used && !p.list) {
          field_of[i] = static_cast<int>(out.cloud.fields.size());
          out.cloud.fields.push_back({p.name, {}});
        }
      }
      const auto n = static_cast<std::size_t>(e.count);
      out.cloud.points.resize(n);
      if (normals) out.cloud.normals.resize(n);
      for (auto& f : out.cloud.fields) f.values.resize(n);
      for (std::size_t v = 0; v < n; ++v) {
        const auto where = body.position();
        const auto at_line = body.line();
        for (std::size_t i = 0; i < e.properties.size(); ++i) {
          const auto& p = e.properties[i];
          if (p.list) {
            const double count = body.value(p.count_type, "a list length");
            if (count < 0) throw IoError(source, "negative list length", at_line);
            for (double k = 0; k < count; k += 1.0) (void)body.value(p.type, "a list entry");
            continue;
          }
          const double x = body.value(p.type, p.name.c_str());
          const int ii = static_cast<int>(i);
          for (int a = 0; a < 3; ++a) {
            if (ii == xyz[a]) out.cloud.points[v][a] = x;
            if (normals && ii == nxyz[a]) out.cloud.normals[v][a] = x;
          }
          if (field_of[i] >= 0)
            out.cloud.fields[static_cast<std::size_t>(field_of[i])].values[v] = x;
        }
        if (!out.cloud.points[v].allFinite()) {
          const std::string why = "vertex " + std::to_string(v) + " has a non-finite coordinate";
          if (binary) throw IoError(source, why, std::nullopt, where);
          throw IoError(source, why, at_line);
        }
        body.end_element();
      }
    } else {
      const bool faces = e.name == "face";
      for (std::uint64_t k = 0; k < e.count; ++k) {
        const auto at_line = body.line();
        const auto where = body.position();
        for (const auto& p : e.properties) {
          if (!p.list) {
            (void)body.value(p.type, p.name.c_str());
            continue;
          }
          const double count = body.value(p.count_type, "a list length");
          if (count < 0 || count > 1e6) throw IoError(source, "impossible list length", at_line);
          const bool indices = faces && (p.name == "vertex_indices" || p.name == "vertex_index");
          std::vector<std::uint32_t> poly;
          for (double j = 0; j < count; j += 1.0) {
            const double idx = body.value(p.type, "a vertex index");
            if (indices) {
              // Checked against the vertex count now, or at the end when the faces come
              // first; `limit` bounds them before that.
              const double limit =
                  seen_vertex ? static_cast<double>(out.cloud.points.size()) : 4294967295.0;
              if (!(idx >= 0 && idx < limit)) {
                const std::string why = "face " + std::to_string(k) + " refers to vertex " +
                                        std::to_string(static_cast<long long>(idx)) + " of " +
                                        std::to_string(out.cloud.points.size());
                if (binary) throw IoError(source, why, std::nullopt, where);
                throw IoError(source, why, at_line);
              }
              poly.push_back(static_cast<std::uint32_t>(idx));
            }
          }
          if (indices && poly.size() < 3) {
            throw IoError(source, "face " + std::to_string(k) + " has fewer than 3 vertices",
                          binary ? std::nullopt : std::optional<std::uint64_t>(at_line),
                          binary ? std::optional<std::uint64_t>(where) : std::nullopt);
          }
          for (std::size_t j = 1; indices && j + 1 < poly.size(); ++j) {
            out.triangles.push_back({poly[0], poly[j], poly[j + 1]});
          }
        }
        body.end_element();
      }
    }
  }
  if (!seen_vertex) throw IoError(source, "the file has no vertex element");
  for (std::size_t t = 0; t < out.triangles.size(); ++t) {  // faces read before the vertices
    for (const auto i : out.triangles[t]) {
      if (i >= out.cloud.points.size()) {
        throw IoError(source, "a face (triangle " + std::to_string(t) + ") refers to vertex " +
                                  std::to_string(i) + " of " +
                                  std::to_string(out.cloud.points.size()));
      }
    }
  }
  // Only whitespace may follow (ASCII); nothing may follow binary data.
  const std::string_view rest = bytes.substr(body.position());
  if (binary ? !rest.empty() : rest.find_first_not_of(" \t\r\n") != std::string_view::npos) {
    throw IoError(source, "data after the last element", std::nullopt, body.position());
  }
  return out;
}

/// Reads a PLY file. Throws IoError.
inline PlyData read_ply(const std::string& path) { return parse_ply(read_file(path), path); }

/// Encodes `cloud` (and optional triangles) as PLY: x, y, z as double, normals when present
/// (nx, ny, nz), then every field as a double property, then faces (uchar count, int indices).
template <class = void>
inline std::string encode_ply(const PointCloud<double>& cloud,
                              PlyFormat format = PlyFormat::binary_little_endian,
                              const std::vector<std::array<std::uint32_t, 3>>& triangles = {}) {
  if (const Outcome o = cloud.validate(); !o)
    throw std::invalid_argument("encode_ply: " + o.message);
  const bool binary = format == PlyFormat::binary_little_endian;
  std::string out = "ply\nformat ";
  out.append(binary ? "binary_little_endian" : "ascii").append(" 1.0\ncomment written by taxel\n");
  out.append("element vertex ").append(std::to_string(cloud.size())).append("\n");
  out.append("property double x\nproperty double y\nproperty double z\n");
  const bool normals = cloud.has_normals();
  if (normals) out.append("property double nx\nproperty double ny\nproperty double nz\n");
  for (const auto& f : cloud.fields) {
    if (f.name.empty() || f.name.find_first_of(" \t\r\n") != std::string::npos) {
      throw std::invalid_argument("encode_ply: field name '" + f.name + "' is empty or has spaces");
    }
    out.append("property double ").append(f.name).append("\n");
  }
  if (!triangles.empty()) {
    out.append("element face ").append(std::to_string(triangles.size())).append("\n");
    out.append("property list uchar int vertex_indices\n");
  }
  out.append("end_header\n");
  const auto put = [&](double v, bool last) {
    if (binary) {
      const auto bits = std::bit_cast<std::uint64_t>(v);
      for (int b = 0; b < 8; ++b) out.push_back(static_cast<char>((bits >> (8 * b)) & 0xFF));
      return;
    }
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, res.ptr);
    out.push_back(last ? '\n' : ' ');
  };
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const bool tail = normals || !cloud.fields.empty();
    for (int a = 0; a < 3; ++a) put(cloud.points[i][a], a == 2 && !tail);
    for (int a = 0; normals && a < 3; ++a) put(cloud.normals[i][a], a == 2 && cloud.fields.empty());
    for (std::size_t f = 0; f < cloud.fields.size(); ++f) {
      put(cloud.fields[f].values[i], f + 1 == cloud.fields.size());
    }
  }
  for (const auto& t : triangles) {
    for (const auto idx : t) {
      if (idx >= cloud.size())
        throw std::invalid_argument("encode_ply: a triangle index is out of range");
    }
    if (binary) {
      out.push_back(3);
      for (const auto idx : t) {
        for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((idx >> (8 * b)) & 0xFF));
      }
    } else {
      out.append("3 ")
          .append(std::to_string(t[0]))
          .append(" ")
          .append(std::to_string(t[1]))
          .append(" ")
          .append(std::to_string(t[2]))
          .append("\n");
    }
  }
  return out;
}

/// Writes a PLY file. Throws IoError on failure, std::invalid_argument for an invalid cloud.
template <class = void>
inline void write_ply(const std::string& path, const PointCloud<double>& cloud,
                      PlyFormat format = PlyFormat::binary_little_endian,
                      const std::vector<std::array<std::uint32_t, 3>>& triangles = {}) {
  write_file(path, encode_ply(cloud, format, triangles));
}

}  // namespace taxel::io
