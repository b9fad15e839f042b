// SPDX-License-Identifier: MIT
// Contact streams as CSV. The first non-comment line is a header naming the columns, in any
// order; one contact per following line. Columns (SI units):
//   time                          acquisition time [s]                  optional (default 0)
//   x, y, z                       position, world frame [m]            required
//   cxx, cxy, cxz, cyy, cyz, czz  covariance [m^2], upper triangle     optional, all six or none
//                                                                      (default (1 mm)^2 I)
//   nx, ny, nz                    unit pad normal                      optional, all three or
//                                                                      none; empty cells: no
//                                                                      normal for that contact
//   pressure                      pressure [Pa] or raw sensor units    optional (default 0)
//   normal_sigma                  angular standard deviation of the    optional (default 0: not
//                                 normal [rad] (Contact::normal_sigma)  stated); empty cell: 0
// Lines starting with '#' and blank lines are skipped; CRLF is accepted. By default the reader
// is strict: unknown or repeated columns, missing values, malformed numbers and non-finite
// positions are refused with the line and column. With ContactsCsvOptions::strict = false,
// unknown columns are ignored (and named in the report) and a bad row is skipped and counted
// (the first one's reason kept), as ContactCloud rejects and counts bad contacts one by one; a
// bad header is still refused. Covariance validity is ContactCloud's business (it rejects and
// counts bad ones), so the reader keeps such contacts.
#pragma once

#include <array>
#include <charconv>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "taxel/core/contact.hpp"
#include "taxel/core/error.hpp"
#include "taxel/io/file.hpp"

namespace taxel::io {

/// Column names in the order encode_contacts_csv writes them.
inline constexpr std::array<std::string_view, 15> kContactColumns{
    "time", "x",   "y",  "z",  "cxx", "cxy",      "cxz",         "cyy",
    "cyz",  "czz", "nx", "ny", "nz",  "pressure", "normal_sigma"};

/// Largest number of contacts the reader accepts (2^26).
inline constexpr std::size_t kMaxContacts = std::size_t{1} << 26;

/// How forgiving the reader is.
struct ContactsCsvOptions {
  bool strict = true;  ///< false: skip bad rows and ignore unknown columns
};

/// What a lenient read left out.
struct ContactsCsvReport {
  std::size_t skipped_rows = 0;              ///< rows skipped as bad
  std::string first_skipped;                 ///< "<source>:<line>: column <c>: why" of the first
  std::vector<std::string> ignored_columns;  ///< unknown column names, in header order
};

/// Parses a contacts CSV held in memory. Throws IoError with "<source>:<line>: column <c>: ...".
/// With `options.strict` false, bad rows and unknown columns go to `report` (when given)
/// instead.
template <class = void>
inline std::vector<Contact<double>> parse_contacts_csv(std::string_view text,
                                                       const std::string& source = "<csv>",
                                                       const ContactsCsvOptions& options = {},
                                                       ContactsCsvReport* report = nullptr) {
  ContactsCsvReport scratch;
  ContactsCsvReport& rep = report != nullptr ? *report : scratch;
  rep = {};
  std::vector<Contact<double>> out;
  std::array<int, kContactColumns.size()> where{};  // column index of each known name, or -1
  where.fill(-1);
  int columns = 0;
  bool have_header = false;
  std::vector<std::string_view> cells;
  LineReader lines(text);
  std::string_view line;
  while (lines.next(line)) {
    const std::uint64_t line_no = lines.line_number();
    if (blank_or_comment(line)) continue;
    cells.clear();
    for (std::size_t c = 0;;) {
      const std::size_t comma = line.find(',', c);
      std::string_view cell =
          line.substr(c, comma == std::string_view::npos ? line.size() - c : comma - c);
      while (!cell.empty() && (cell.front() == ' ' || cell.front() == '\t')) cell.remove_prefix(1);
      while (!cell.empty() && (cell.back() == ' ' || cell.back() == '\t')) cell.remove_suffix(1);
      cells.push_back(cell);
      if (comma == std::string_view::npos) break;
      c = comma + 1;
    }
    const auto fail = [&](std::size_t column, const std::string& why) {
      throw IoError(source, "column " + std::to_string(column + 1) + ": " + why, line_no);
    };
    if (!have_header) {
      for (std::size_t c = 0; c < cells.size(); ++c) {
        std::size_t k = 0;
        while (k < kContactColumns.size() && kContactColumns[k] != cells[c]) ++k;
        if (k == kContactColumns.size() && !options.strict) {
          rep.ignored_columns.emplace_back(cells[c]);
          continue;
        }
        if (k == kContactColumns.size()) {
          std::string known;
          for (const std::string_view name : kContactColumns) {
            known += known.empty() ? "" : ", ";
            known += name;
          }
          fail(c, "unknown column '" + std::string(cells[c].substr(0, 24)) + "' (known: " + known +
                      ")");
        }
        if (where[k] >= 0) fail(c, "column '" + std::string(cells[c]) + "' appears twice");
        where[k] = static_cast<int>(c);
      }
      if (where[1] < 0 || where[2] < 0 || where[3] < 0) {
        throw IoError(source, "the header needs columns x, y and z", line_no);
      }
      int cov = 0, nrm = 0;
      for (std::size_t k = 4; k < 10; ++k) cov += where[k] >= 0 ? 1 : 0;
      for (std::size_t k = 10; k < 13; ++k) nrm += where[k] >= 0 ? 1 : 0;
      if (cov != 0 && cov != 6)
        throw IoError(source, "covariance needs all six columns or none", line_no);
      if (nrm != 0 && nrm != 3)
        throw IoError(source, "the normal needs nx, ny and nz or none", line_no);
      columns = static_cast<int>(cells.size());
      have_header = true;
      continue;
    }
    if (out.size() >= kMaxContacts) {
      throw IoError(source, "more than " + std::to_string(kMaxContacts) + " contacts", line_no);
    }
    try {
      if (static_cast<int>(cells.size()) != columns) {
        throw IoError(source,
                      "row has " + std::to_string(cells.size()) + " values; the header has " +
                          std::to_string(columns),
                      line_no);
      }
      const auto value = [&](std::size_t k, bool allow_empty) -> std::optional<double> {
        const auto c = static_cast<std::size_t>(where[k]);
        const std::string_view cell = cells[c];
        if (cell.empty()) {
          if (allow_empty) return std::nullopt;
          fail(c, std::string(kContactColumns[k]) + " is empty");
        }
        double v = 0.0;
        const auto res = std::from_chars(cell.data(), cell.data() + cell.size(), v);
        if (res.ec != std::errc() || res.ptr != cell.data() + cell.size()) {
          fail(c, "'" + std::string(cell.substr(0, 24)) + "' is not a number");
        }
        return v;
      };
      Contact<double> ct;
      for (int a = 0; a < 3; ++a) ct.position[a] = *value(static_cast<std::size_t>(1 + a), false);
      if (!ct.position.allFinite())
        fail(static_cast<std::size_t>(where[1]), "the position is not finite");
      if (where[0] >= 0) ct.time = *value(0, false);
      if (where[4] >= 0) {
        const double xx = *value(4, false), xy = *value(5, false), xz = *value(6, false);
        const double yy = *value(7, false), yz = *value(8, false), zz = *value(9, false);
        ct.covariance << xx, xy, xz, xy, yy, yz, xz, yz, zz;
      }
      if (where[10] >= 0) {
        const auto nx = value(10, true), ny = value(11, true), nz = value(12, true);
        if (nx && ny && nz) {
          ct.normal = Vec3d(*nx, *ny, *nz);
        } else if (nx || ny || nz) {
          fail(static_cast<std::size_t>(where[10]),
               "a normal needs nx, ny and nz, or none of them");
        }
      }
      if (where[13] >= 0) ct.pressure = *value(13, false);
      if (where[14] >= 0) ct.normal_sigma = value(14, true).value_or(0.0);
      out.push_back(ct);
    } catch (const IoError& e) {
      if (options.strict) throw;
      if (rep.skipped_rows++ == 0) rep.first_skipped = e.what();
    }
  }
  if (!have_header) throw IoError(source, "no header line (expected e.g. 'time,x,y,z')");
  return out;
}

/// Reads a contacts CSV file. Throws IoError (see parse_contacts_csv for `options`).
template <class = void>
inline std::vector<Contact<double>> read_contacts_csv(const std::string& path,
                                                      const ContactsCsvOptions& options = {},
                                                      ContactsCsvReport* report = nullptr) {
  return parse_contacts_csv(read_file(path), path, options, report);
}

/// Encodes contacts with every column (kContactColumns); empty normal cells for contacts
/// without one. Numbers in shortest round-trip form.
template <class = void>
inline std::string encode_contacts_csv(const std::vector<Contact<double>>& contacts) {
  std::string out;
  for (std::size_t k = 0; k < kContactColumns.size(); ++k) {
    out.append(k ? "," : "").append(kContactColumns[k]);
  }
  out.push_back('\n');
  char buf[32];
  const auto put = [&](double v) {
    const auto res = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, res.ptr);
  };
  for (const auto& c : contacts) {
    put(c.time);
    for (int a = 0; a < 3; ++a) {
      out.push_back(',');
      put(c.position[a]);
    }
    for (const auto& [r, col] : {std::pair{0, 0}, {0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 2}}) {
      out.push_back(',');
      put(c.covariance(r, col));
    }
    for (int a = 0; a < 3; ++a) {
      out.push_back(',');
      if (c.normal) put((*c.normal)[a]);
    }
    out.push_back(',');
    put(c.pressure);
    out.push_back(',');
    put(c.normal_sigma);
    out.push_back('\n');
  }
  return out;
}

/// Writes a contacts CSV file. Throws IoError.
template <class = void>
inline void write_contacts_csv(const std::string& path,
                               const std::vector<Contact<double>>& contacts) {
  write_file(path, encode_contacts_csv(contacts));
}

}  // namespace taxel::io
