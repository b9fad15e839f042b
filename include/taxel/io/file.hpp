// SPDX-License-Identifier: MIT
// Whole-file reading and writing with errors that name the file (taxel::IoError).
#pragma once

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <string>
#include <string_view>

#include "taxel/core/error.hpp"

namespace taxel::io {

/// Splits text into lines ending in LF or CRLF (the line ending is not part of a line) and
/// counts them from 1; the last line may lack its ending. The text readers share it.
class LineReader {
 public:
  explicit LineReader(std::string_view text) noexcept : text_(text) {}

  /// The next line; false once the text is used up.
  bool next(std::string_view& line) noexcept {
    if (pos_ >= text_.size()) return false;
    const std::size_t nl = text_.find('\n', pos_);
    const std::size_t end = nl == std::string_view::npos ? text_.size() : nl;
    line = text_.substr(pos_, end - pos_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos_ = nl == std::string_view::npos ? text_.size() : nl + 1;
    ++number_;
    return true;
  }
  /// Number of the line `next` returned last (0 before the first).
  [[nodiscard]] std::uint64_t line_number() const noexcept { return number_; }
  /// Offset of the byte after the last line returned (where binary data may follow).
  [[nodiscard]] std::size_t offset() const noexcept { return pos_; }

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::uint64_t number_ = 0;
};

/// True for a line that is empty, blank, or whose first non-blank character is '#'.
inline bool blank_or_comment(std::string_view line) noexcept {
  const auto first = line.find_first_not_of(" \t");
  return first == std::string_view::npos || line[first] == '#';
}

/// Largest file the readers accept (1 GiB); larger inputs are refused, not read.
inline constexpr std::uint64_t kMaxFileBytes = std::uint64_t{1} << 30;

/// Reads a whole file into memory. Throws IoError when it cannot be opened or read, or is
/// larger than `max_bytes`.
inline std::string read_file(const std::string& path, std::uint64_t max_bytes = kMaxFileBytes) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  const std::streamoff size = in.tellg();
  if (size < 0) throw IoError(path, "cannot determine the file size");
  if (static_cast<std::uint64_t>(size) > max_bytes) {
    throw IoError(path, "file is " + std::to_string(size) + " bytes; the limit is " +
                            std::to_string(max_bytes));
  }
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.seekg(0);
  if (size > 0 && !in.read(bytes.data(), size)) throw IoError(path, "read failed");
  return bytes;
}

/// Writes `bytes` to `path`, replacing it. Throws IoError on failure.
inline void write_file(const std::string& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.flush();
  if (!out) throw IoError(path, "write failed");
}

/// Lower-case extension of a path including the dot ("" when there is none).
inline std::string extension(std::string_view path) {
  const auto slash = path.find_last_of("/\\");
  const auto dot = path.find_last_of('.');
  if (dot == std::string_view::npos || (slash != std::string_view::npos && dot < slash)) return {};
  std::string ext(path.substr(dot));
  for (char& ch : ext) ch = static_cast<char>(ch >= 'A' && ch <= 'Z' ? ch - 'A' + 'a' : ch);
  return ext;
}

}  // namespace taxel::io
