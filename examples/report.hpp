// SPDX-License-Identifier: MIT
// The results of a tool as text, JSON or CSV (--format): one record, or an array of records,
// built as JSON objects (nlohmann::json) and rendered by one function, so that every tool's
// formats agree.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace taxel_cli {

/// How a tool prints its results: `text` for people, `json` (one document, from nlohmann::json)
/// and `csv` (a header and a row per record) for programs.
enum class Format { text, json, csv };

inline Format to_format(std::string_view v) {
  return v == "json" ? Format::json : (v == "csv" ? Format::csv : Format::text);
}

/// A tool's results: one record (a JSON object) or several (an array of objects), kept in the
/// order the fields were set.
using Json = nlohmann::ordered_json;

namespace detail {
inline void flatten(const Json& j, const std::string& key, std::vector<std::string>& keys,
                    std::vector<const Json*>& values) {
  if (j.is_object() && !j.empty()) {
    for (const auto& [k, v] : j.items()) flatten(v, key.empty() ? k : key + "." + k, keys, values);
  } else if (j.is_array() && !j.empty() && !j.front().is_structured()) {
    for (std::size_t i = 0; i < j.size(); ++i) {
      flatten(j[i], key + "." + std::to_string(i), keys, values);
    }
  } else {
    keys.push_back(key);
    values.push_back(&j);
  }
}
inline std::string scalar(const Json& v, bool csv) {
  if (v.is_null()) return csv ? "" : "nan";
  if (v.is_string()) {
    const std::string& s = v.get_ref<const std::string&>();
    if (!csv || s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string q = "\"";
    for (const char c : s) {
      if (c == '"') q += '"';
      q += c;
    }
    return q + "\"";
  }
  if (v.is_number_float()) {  // shortest round trip: 128, not 128.0; nan and inf as words
    char buf[32];
    const auto res = std::to_chars(buf, buf + sizeof buf, v.get<double>());
    return std::string(buf, res.ptr);
  }
  if (v.is_structured()) return v.dump(-1, ' ', false, Json::error_handler_t::replace);
  return v.dump();
}
}  // namespace detail

/// A rigid transform as report fields: "transform" (16 numbers, row-major), "translation"
/// (x, y, z) and the rotation as "axis" (unit vector) and "angle" [rad].
inline Json pose_fields(const Eigen::Isometry3d& T) {
  Json j = Json::object();
  Json m = Json::array();
  for (int k = 0; k < 16; ++k) m.push_back(T.matrix()(k / 4, k % 4));
  j["transform"] = std::move(m);
  const Eigen::Vector3d t = T.translation();
  j["translation"] = {t.x(), t.y(), t.z()};
  const Eigen::AngleAxisd aa(T.rotation());
  const Eigen::Vector3d axis = aa.angle() > 0 ? aa.axis() : Eigen::Vector3d::UnitZ();
  j["axis"] = {axis.x(), axis.y(), axis.z()};
  j["angle"] = aa.angle();
  return j;
}

/// `report` as `format`:
///  - json: the document, indented (NaN and infinities become null, as JSON has neither);
///  - csv: a header of the flattened field names ("a.b", "m.0") and one row per record;
///  - text: "name value" per field, records separated by a blank line.
inline std::string render(const Json& report, Format format) {
  if (format == Format::json) {
    return report.dump(2, ' ', false, Json::error_handler_t::replace) + "\n";
  }
  const bool csv = format == Format::csv;
  std::vector<Json> records;
  if (report.is_array()) {
    records.assign(report.begin(), report.end());
  } else {
    records.push_back(report);
  }
  std::vector<std::vector<std::string>> keys(records.size());
  std::vector<std::vector<const Json*>> values(records.size());
  std::vector<std::string> header;  // every field of every record, in order of first appearance
  for (std::size_t r = 0; r < records.size(); ++r) {
    detail::flatten(records[r], "", keys[r], values[r]);
    for (const std::string& k : keys[r]) {
      if (std::find(header.begin(), header.end(), k) == header.end()) header.push_back(k);
    }
  }
  std::string out;
  if (csv) {
    for (std::size_t i = 0; i < header.size(); ++i) out.append(i ? "," : "").append(header[i]);
    out += "\n";
  }
  for (std::size_t r = 0; r < records.size(); ++r) {
    if (csv) {  // a record without one of the fields leaves its cell empty
      for (std::size_t i = 0; i < header.size(); ++i) {
        const auto it = std::find(keys[r].begin(), keys[r].end(), header[i]);
        const std::size_t k = static_cast<std::size_t>(it - keys[r].begin());
        if (i > 0) out += ',';
        if (it != keys[r].end()) out.append(detail::scalar(*values[r][k], true));
      }
      out += "\n";
    } else {
      if (r > 0) out += "\n";
      for (std::size_t i = 0; i < keys[r].size(); ++i) {
        out.append(keys[r][i])
            .append(" ")
            .append(detail::scalar(*values[r][i], false))
            .append("\n");
      }
    }
  }
  return out;
}

}  // namespace taxel_cli
