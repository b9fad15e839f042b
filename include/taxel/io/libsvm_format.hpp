// SPDX-License-Identifier: MIT
// libsvm / svmlight sparse text data sets: `<label> [qid:<group>] <index>:<value> ...` per line,
// indices 1-based and ascending, `#` starting a comment. Read strictly into a dense
// taxel::learn::Dataset (every error names the line and column) and written back.
#pragma once

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "taxel/core/error.hpp"
#include "taxel/io/file.hpp"
#include "taxel/learn/dataset.hpp"

namespace taxel::io {

/// Options of the libsvm reader.
struct LibsvmReadOptions {
  /// Features per sample: 0 takes the largest index in the file; a positive value fixes the
  /// width (an index above it is an error), as when reading a test set for a trained model.
  long long dims = 0;
  /// Largest dense matrix (rows x features) the reader will allocate: 2^24 values (128 MiB)
  /// by default, so a small file naming a huge feature index is refused, not expanded.
  std::uint64_t max_values = std::uint64_t{1} << 24;
};

namespace detail {
inline bool libsvm_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }
// A token for an error message: at most 24 characters, non-printable bytes as \xNN.
inline std::string libsvm_quote(std::string_view t) {
  std::string q = "`";
  for (std::size_t i = 0; i < t.size() && i < 24; ++i) {
    const auto c = static_cast<unsigned char>(t[i]);
    if (c >= 0x20 && c < 0x7f) {
      q.push_back(static_cast<char>(c));
    } else {
      constexpr char kHex[] = "0123456789abcdef";
      q.append("\\x").push_back(kHex[c >> 4]);
      q.push_back(kHex[c & 15]);
    }
  }
  if (t.size() > 24) q.append("...");
  q.push_back('`');
  return q;
}
}  // namespace detail

/// Parses libsvm text into a dense data set. Labels must be integers (`+1`, `-1`, `3`, `2.0`);
/// `qid:<n>` after the label becomes the sample's group id (all lines or none). Blank lines are
/// skipped. Throws taxel::IoError "<source>:<line>: column <c>: <what was expected>".
template <class = void>
inline learn::Dataset parse_libsvm(std::string_view text, const std::string& source = "<libsvm>",
                                   const LibsvmReadOptions& opt = {}) {
  struct Entry {
    std::uint64_t row;
    long long index;
    double value;
  };
  std::vector<Entry> entries;
  std::vector<int> labels;
  std::vector<int> groups;
  long long max_index = 0;
  std::uint64_t line_no = 0;
  std::size_t pos = 0;
  bool any_qid = false;
  while (pos < text.size()) {
    ++line_no;
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (const std::size_t hash = line.find('#'); hash != std::string_view::npos) {
      line = line.substr(0, hash);
    }
    std::size_t p = 0;
    const auto fail = [&](std::size_t col, const std::string& why) {
      throw IoError(source, "column " + std::to_string(col + 1) + ": " + why, line_no);
    };
    const auto next_token = [&](std::size_t& start) {
      while (p < line.size() && detail::libsvm_space(line[p])) ++p;
      start = p;
      while (p < line.size() && !detail::libsvm_space(line[p])) ++p;
      return line.substr(start, p - start);
    };
    std::size_t col = 0;
    std::string_view tok = next_token(col);
    if (tok.empty()) continue;  // blank or comment-only line
    if (tok.find(':') != std::string_view::npos) fail(col, "expected a label before the features");
    {
      std::string_view t = tok;
      if (t.size() > 1 && t[0] == '+') t.remove_prefix(1);
      double v = 0.0;
      const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
      if (r.ec != std::errc{} || r.ptr != t.data() + t.size() || !std::isfinite(v)) {
        fail(col, "expected a numeric label, found " + detail::libsvm_quote(tok));
      }
      if (v != std::floor(v) || std::fabs(v) > 2147483647.0) {
        fail(col,
             "label " + detail::libsvm_quote(tok) + " is not an integer (class labels must be)");
      }
      labels.push_back(static_cast<int>(v));
    }
    const std::uint64_t row = labels.size() - 1;
    long long last = 0;
    bool first_feature = true;
    for (;;) {
      tok = next_token(col);
      if (tok.empty()) break;
      const std::size_t colon = tok.find(':');
      if (colon == std::string_view::npos) {
        fail(col, "expected <index>:<value>, found " + detail::libsvm_quote(tok));
      }
      const std::string_view key = tok.substr(0, colon);
      const std::string_view val = tok.substr(colon + 1);
      if (key == "qid") {
        if (!first_feature) fail(col, "qid must come right after the label");
        int g = 0;
        const auto r = std::from_chars(val.data(), val.data() + val.size(), g);
        if (r.ec != std::errc{} || r.ptr != val.data() + val.size()) {
          fail(col + colon + 1, "expected an integer qid, found " + detail::libsvm_quote(val));
        }
        if (row > 0 && !any_qid) fail(col, "qid on some lines only");
        any_qid = true;
        groups.push_back(g);
        first_feature = false;
        continue;
      }
      first_feature = false;
      long long index = 0;
      const auto ri = std::from_chars(key.data(), key.data() + key.size(), index);
      if (ri.ec != std::errc{} || ri.ptr != key.data() + key.size() || index < 1) {
        fail(col, "expected a feature index >= 1, found " + detail::libsvm_quote(key));
      }
      if (index <= last) {
        fail(col, "feature index " + std::to_string(index) + " does not follow " +
                      std::to_string(last) + " (indices must ascend)");
      }
      if (opt.dims > 0 && index > opt.dims) {
        fail(col, "feature index " + std::to_string(index) + " exceeds the " +
                      std::to_string(opt.dims) + " features expected");
      }
      double v = 0.0;
      const auto rv = std::from_chars(val.data(), val.data() + val.size(), v);
      if (val.empty() || rv.ec != std::errc{} || rv.ptr != val.data() + val.size()) {
        fail(col + colon + 1, "expected a number after " +
                                  detail::libsvm_quote(tok.substr(0, colon + 1)) + ", found " +
                                  detail::libsvm_quote(val));
      }
      if (!std::isfinite(v)) {
        fail(col + colon + 1, "feature " + std::to_string(index) + " is not finite");
      }
      last = index;
      max_index = std::max(max_index, index);
      if (v != 0.0) entries.push_back({row, index, v});
    }
    if (any_qid && groups.size() != labels.size()) fail(0, "qid on some lines only");
  }
  if (labels.empty()) throw IoError(source, "no samples (the file is empty)");
  const long long dims = opt.dims > 0 ? opt.dims : max_index;
  if (dims == 0) throw IoError(source, "no features on any line");
  if (static_cast<double>(labels.size()) * static_cast<double>(dims) >
      static_cast<double>(opt.max_values)) {
    throw IoError(source, std::to_string(labels.size()) + " samples x " + std::to_string(dims) +
                              " features exceed the dense limit of " +
                              std::to_string(opt.max_values) +
                              " values (LibsvmReadOptions::max_values)");
  }
  learn::Dataset d;
  d.x = learn::FeatureMatrix::Zero(static_cast<Eigen::Index>(labels.size()),
                                   static_cast<Eigen::Index>(dims));
  for (const Entry& e : entries) {
    d.x(static_cast<Eigen::Index>(e.row), static_cast<Eigen::Index>(e.index - 1)) = e.value;
  }
  d.y = std::move(labels);
  d.groups = std::move(groups);
  return d;
}

/// Reads a libsvm file (see parse_libsvm).
template <class = void>
inline learn::Dataset read_libsvm(const std::string& path, const LibsvmReadOptions& opt = {}) {
  return parse_libsvm(read_file(path), path, opt);
}

/// Writes a data set as libsvm text: non-zero features only, numbers that round-trip exactly,
/// `qid:` when the set has group ids.
template <class = void>
inline std::string encode_libsvm(const learn::DatasetView& d) {
  std::string s;
  char buf[40];
  for (Eigen::Index r = 0; r < d.rows(); ++r) {
    s.append(std::to_string(d.y[static_cast<std::size_t>(r)]));
    if (!d.groups.empty()) {
      s.append(" qid:").append(std::to_string(d.groups[static_cast<std::size_t>(r)]));
    }
    for (Eigen::Index c = 0; c < d.dims(); ++c) {
      const double v = d.x(r, c);
      if (v == 0.0) continue;
      s.append(" ").append(std::to_string(c + 1)).append(":");
      const auto res = std::to_chars(buf, buf + sizeof buf, v);
      s.append(buf, res.ptr);
    }
    s.append("\n");
  }
  return s;
}

}  // namespace taxel::io
