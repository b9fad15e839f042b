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
//   footprint_sigma               the footprint part of the covariance  optional (default 0: all
//                                 across the normal [m]                 scatter); empty cell: 0
//                                 (Contact::footprint_sigma)
// Lines starting with '#' and blank lines are skipped; LF, CRLF and lone-CR line endings and a
// leading UTF-8 byte-order mark are accepted. By default the reader is strict: unknown or
// repeated columns, missing values, malformed numbers and a non-finite position, time or
// pressure are refused with the line and column. With ContactsCsvOptions::strict = false,
// unknown columns are ignored (and named in the report) and a bad row is skipped and counted
// (the first one's reason kept), as ContactCloud rejects and counts bad contacts one by one; a
// bad header is still refused. Covariance validity is ContactCloud's business (it rejects and
// counts bad ones), so the reader keeps such contacts.
#pragma once

#include <array>
#include <charconv>
#include <cmath>
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
inline constexpr std::array<std::string_view, 16> kContactColumns{
    "time", "x",   "y",  "z",  "cxx", "cxy",      "cxz",          "cyy",
    "cyz",  "czz", "nx", "ny", "nz",  "pressure", "normal_sigma", "footprint_sigma"};

/// Largest number of contacts parse_contacts_csv and read_contacts_csv return (2^26); the
/// streaming ContactsCsvReader has no limit.
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

/// The contacts CSV grammar, one line at a time, shared by the in-memory and the streaming
/// readers: the first line that is neither blank nor a comment is the header.
class ContactsCsvParser {
 public:
  /// `source` names the input in messages; bad rows and unknown columns of a lenient read go to
  /// `report` (when given).
  explicit ContactsCsvParser(std::string source, const ContactsCsvOptions& options = {},
                             ContactsCsvReport* report = nullptr)
      : source_(std::move(source)),
        options_(options),
        report_(report != nullptr ? report : &scratch_) {
    *report_ = {};
    where_.fill(-1);
  }
  ContactsCsvParser(const ContactsCsvParser&) = delete;
  ContactsCsvParser& operator=(const ContactsCsvParser&) = delete;

  /// Reads line `line_no` (without its ending); true when it holds a contact, stored in `out`.
  /// Throws IoError "<source>:<line>: column <c>: ..." for a bad header, and for a bad row
  /// unless the read is lenient.
  bool line(std::string_view line, std::uint64_t line_no, Contact<double>& out) {
    if (blank_or_comment(line)) return false;
    split(line);
    if (!have_header_) {
      header(line_no);
      return false;
    }
    try {
      row(line_no, out);
      return true;
    } catch (const IoError& e) {
      if (options_.strict) throw;
      if (report_->skipped_rows++ == 0) report_->first_skipped = e.what();
      return false;
    }
  }

  /// Throws IoError when no header was read.
  void finish() const {
    if (!have_header_) throw IoError(source_, "no header line (expected e.g. 'time,x,y,z')");
  }

 private:
  void split(std::string_view line) {
    cells_.clear();
    for (std::size_t c = 0;;) {
      const std::size_t comma = line.find(',', c);
      std::string_view cell =
          line.substr(c, comma == std::string_view::npos ? line.size() - c : comma - c);
      while (!cell.empty() && (cell.front() == ' ' || cell.front() == '\t')) cell.remove_prefix(1);
      while (!cell.empty() && (cell.back() == ' ' || cell.back() == '\t')) cell.remove_suffix(1);
      cells_.push_back(cell);
      if (comma == std::string_view::npos) break;
      c = comma + 1;
    }
  }

  [[noreturn]] void fail(std::size_t column, const std::string& why, std::uint64_t line_no) const {
    throw IoError(source_, "column " + std::to_string(column + 1) + ": " + why, line_no);
  }

  void header(std::uint64_t line_no) {
    for (std::size_t c = 0; c < cells_.size(); ++c) {
      std::size_t k = 0;
      while (k < kContactColumns.size() && kContactColumns[k] != cells_[c]) ++k;
      if (k == kContactColumns.size() && !options_.strict) {
        report_->ignored_columns.emplace_back(cells_[c]);
        continue;
      }
      if (k == kContactColumns.size()) {
        std::string known;
        for (const std::string_view name : kContactColumns) {
          known += known.empty() ? "" : ", ";
          known += name;
        }
        fail(c,
             "unknown column '" + std::string(cells_[c].substr(0, 24)) + "' (known: " + known + ")",
             line_no);
      }
      if (where_[k] >= 0) fail(c, "column '" + std::string(cells_[c]) + "' appears twice", line_no);
      where_[k] = static_cast<int>(c);
    }
    if (where_[1] < 0 || where_[2] < 0 || where_[3] < 0) {
      throw IoError(source_, "the header needs columns x, y and z", line_no);
    }
    int cov = 0, nrm = 0;
    for (std::size_t k = 4; k < 10; ++k) cov += where_[k] >= 0 ? 1 : 0;
    for (std::size_t k = 10; k < 13; ++k) nrm += where_[k] >= 0 ? 1 : 0;
    if (cov != 0 && cov != 6)
      throw IoError(source_, "covariance needs all six columns or none", line_no);
    if (nrm != 0 && nrm != 3)
      throw IoError(source_, "the normal needs nx, ny and nz or none", line_no);
    columns_ = cells_.size();
    have_header_ = true;
  }

  void row(std::uint64_t line_no, Contact<double>& ct) {
    if (cells_.size() != columns_) {
      throw IoError(source_,
                    "row has " + std::to_string(cells_.size()) + " values; the header has " +
                        std::to_string(columns_),
                    line_no);
    }
    const auto value = [&](std::size_t k, bool allow_empty) -> std::optional<double> {
      const auto c = static_cast<std::size_t>(where_[k]);
      const std::string_view cell = cells_[c];
      if (cell.empty()) {
        if (allow_empty) return std::nullopt;
        fail(c, std::string(kContactColumns[k]) + " is empty", line_no);
      }
      double v = 0.0;
      const auto res = std::from_chars(cell.data(), cell.data() + cell.size(), v);
      if (res.ec != std::errc() || res.ptr != cell.data() + cell.size()) {
        fail(c, "'" + std::string(cell.substr(0, 24)) + "' is not a number", line_no);
      }
      return v;
    };
    // Time and pressure are the row's own: a NaN there is a bad row, as a NaN position is.
    const auto finite = [&](std::size_t k) {
      const double v = *value(k, false);
      if (!std::isfinite(v)) {
        fail(static_cast<std::size_t>(where_[k]),
             std::string(kContactColumns[k]) + " is not finite", line_no);
      }
      return v;
    };
    ct = Contact<double>{};
    for (int a = 0; a < 3; ++a) ct.position[a] = *value(static_cast<std::size_t>(1 + a), false);
    if (!ct.position.allFinite())
      fail(static_cast<std::size_t>(where_[1]), "the position is not finite", line_no);
    if (where_[0] >= 0) ct.time = finite(0);
    if (where_[4] >= 0) {
      const double xx = *value(4, false), xy = *value(5, false), xz = *value(6, false);
      const double yy = *value(7, false), yz = *value(8, false), zz = *value(9, false);
      ct.covariance << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    }
    if (where_[10] >= 0) {
      const auto nx = value(10, true), ny = value(11, true), nz = value(12, true);
      if (nx && ny && nz) {
        ct.normal = Vec3d(*nx, *ny, *nz);
      } else if (nx || ny || nz) {
        fail(static_cast<std::size_t>(where_[10]), "a normal needs nx, ny and nz, or none of them",
             line_no);
      }
    }
    if (where_[13] >= 0) ct.pressure = finite(13);
    if (where_[14] >= 0) ct.normal_sigma = value(14, true).value_or(0.0);
    if (where_[15] >= 0) ct.footprint_sigma = value(15, true).value_or(0.0);
  }

  std::string source_;
  ContactsCsvOptions options_;
  ContactsCsvReport scratch_;
  ContactsCsvReport* report_;
  std::array<int, kContactColumns.size()> where_{};  // column index of each known name, or -1
  std::size_t columns_ = 0;
  bool have_header_ = false;
  std::vector<std::string_view> cells_;
};

/// Parses a contacts CSV held in memory. Throws IoError with "<source>:<line>: column <c>: ...".
/// With `options.strict` false, bad rows and unknown columns go to `report` (when given)
/// instead.
template <class = void>
inline std::vector<Contact<double>> parse_contacts_csv(std::string_view text,
                                                       const std::string& source = "<csv>",
                                                       const ContactsCsvOptions& options = {},
                                                       ContactsCsvReport* report = nullptr) {
  ContactsCsvParser parser(source, options, report);
  std::vector<Contact<double>> out;
  LineReader lines(text);
  std::string_view line;
  Contact<double> c;
  while (lines.next(line)) {
    if (!parser.line(line, lines.line_number(), c)) continue;
    if (out.size() >= kMaxContacts) {
      throw IoError(source, "more than " + std::to_string(kMaxContacts) + " contacts",
                    lines.line_number());
    }
    out.push_back(c);
  }
  parser.finish();
  return out;
}

/// Reads a contacts CSV file a block at a time, so that a stream of any length is read in
/// memory independent of its size: the caller takes the contacts in batches (fusing each
/// batch before reading the next). Throws IoError as parse_contacts_csv does.
class ContactsCsvReader {
 public:
  /// Opens `path` (a file, a pipe, /dev/stdin); `source` names it in messages.
  explicit ContactsCsvReader(const std::string& path, const ContactsCsvOptions& options = {},
                             std::string source = {})
      : lines_(path, source), parser_(source.empty() ? path : source, options, &report_) {}

  /// Appends up to `max` contacts to `out`; false once the file is used up (after the last
  /// contacts were appended).
  bool read(std::vector<Contact<double>>& out, std::size_t max) {
    std::string_view line;
    Contact<double> c;
    for (std::size_t got = 0; got < max;) {
      if (!lines_.next(line)) {
        parser_.finish();
        return false;
      }
      if (parser_.line(line, lines_.line_number(), c)) {
        out.push_back(c);
        ++got;
      }
    }
    return true;
  }

  /// What a lenient read left out so far.
  [[nodiscard]] const ContactsCsvReport& report() const noexcept { return report_; }

 private:
  FileLineReader lines_;
  ContactsCsvReport report_;
  ContactsCsvParser parser_;
};

/// Reads a contacts CSV file. Throws IoError (see parse_contacts_csv for `options`).
template <class = void>
inline std::vector<Contact<double>> read_contacts_csv(const std::string& path,
                                                      const ContactsCsvOptions& options = {},
                                                      ContactsCsvReport* report = nullptr) {
  ContactsCsvReader reader(path, options);
  std::vector<Contact<double>> out;
  while (reader.read(out, std::size_t{1} << 16)) {
    if (out.size() > kMaxContacts) {
      throw IoError(path, "more than " + std::to_string(kMaxContacts) + " contacts");
    }
  }
  if (report != nullptr) *report = reader.report();
  return out;
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
    out.push_back(',');
    put(c.footprint_sigma);
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
