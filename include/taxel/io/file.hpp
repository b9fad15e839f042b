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
