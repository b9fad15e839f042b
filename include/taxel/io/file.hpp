// SPDX-License-Identifier: MIT
// Whole-file reading and writing with errors that name the file (taxel::IoError). Writes are
// atomic on POSIX systems: a temporary file beside the target, flushed, then renamed.
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
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

/// Reads a whole file into memory: a regular file, or a pipe or device (standard input,
/// `<(...)`) read to its end. Throws IoError when it cannot be opened or read, is a folder, or
/// is larger than `max_bytes`.
inline std::string read_file(const std::string& path, std::uint64_t max_bytes = kMaxFileBytes) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw IoError(path, std::string("cannot open for reading: ") + std::strerror(errno));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  struct ::stat st {};
  if (::fstat(fd, &st) != 0)
    throw IoError(path, std::string("cannot stat: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw IoError(path, "is a folder, not a file");
  const auto too_large = [&](std::uint64_t size) {
    return IoError(path, "file is " + std::to_string(size) + " bytes or more; the limit is " +
                             std::to_string(max_bytes) + " bytes");
  };
  std::string bytes;
  if (S_ISREG(st.st_mode)) {
    if (static_cast<std::uint64_t>(st.st_size) > max_bytes)
      throw too_large(static_cast<std::uint64_t>(st.st_size));
    bytes.reserve(static_cast<std::size_t>(st.st_size));
  }
  char buffer[1 << 16];
  for (;;) {
    const ::ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw IoError(path, std::string("read failed: ") + std::strerror(errno));
    }
    if (n == 0) break;
    if (bytes.size() + static_cast<std::size_t>(n) > max_bytes) {
      throw too_large(bytes.size() + static_cast<std::size_t>(n));
    }
    bytes.append(buffer, static_cast<std::size_t>(n));
  }
  return bytes;
}

namespace detail {

/// Writes all of `bytes` to the open descriptor `fd`, retrying short writes and EINTR; returns
/// 0 or the errno of the failure.
inline int write_all(int fd, std::string_view bytes) noexcept {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const std::size_t chunk = std::min<std::size_t>(bytes.size() - done, std::size_t{1} << 30);
    const ::ssize_t n = ::write(fd, bytes.data() + done, chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    done += static_cast<std::size_t>(n);
  }
  return 0;
}

/// A name for a temporary file beside `target` that no other writer in this or another
/// process picks: the target's name, the process id and a counter.
inline std::string temporary_beside(const std::string& target) {
  static std::atomic<unsigned long> counter{0};
  const auto slash = target.find_last_of('/');
  const std::string dir = slash == std::string::npos ? std::string() : target.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? target : target.substr(slash + 1);
  return dir + "." + name + ".tmp." + std::to_string(static_cast<long>(::getpid())) + "." +
         std::to_string(counter.fetch_add(1));
}

}  // namespace detail

/// Writes `bytes` to `path` whole or not at all. A regular file (or a new one) is written to a
/// temporary file in the same folder, flushed to the device (fsync), checked, and renamed over
/// `path`: after any failure the previous file is intact and no partial file is left. A
/// symbolic link is followed (the file it names is replaced, the link stays). A path that names
/// a device or a pipe (`/dev/stdout`, `/dev/null`) is written in place and every write checked.
/// Throws IoError naming the file and the reason (for example "No space left on device").
/// Thread-safe for distinct paths.
inline void write_file(const std::string& path, std::string_view bytes) {
  if (path.empty()) throw IoError(path, "cannot write: the file name is empty");
  std::string target = path;
  struct ::stat st {};
  bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw IoError(path, "cannot write: it is a folder");
  if (exists && !S_ISREG(st.st_mode)) {  // a device or a pipe: there is nothing to replace
    const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0)
      throw IoError(path, std::string("cannot open for writing: ") + std::strerror(errno));
    int err = detail::write_all(fd, bytes);
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) throw IoError(path, std::string("write failed: ") + std::strerror(err));
    return;
  }
  struct ::stat lst {};
  if (exists && ::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode)) {
    if (char* real = ::realpath(path.c_str(), nullptr)) {
      target = real;
      std::free(real);
    }
  }
  const std::string tmp = detail::temporary_beside(target);
  // 0666 minus the umask, as a plain open would; an existing file keeps its permissions.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
    throw IoError(path, std::string("cannot create a file beside it: ") + std::strerror(errno));
  int err = detail::write_all(fd, bytes);
  if (err == 0 && exists) (void)::fchmod(fd, st.st_mode & 07777);
  if (err == 0 && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && ::rename(tmp.c_str(), target.c_str()) != 0) err = errno;
  if (err != 0) {
    ::unlink(tmp.c_str());
    throw IoError(path, std::string("write failed (the previous file, if any, is unchanged): ") +
                            std::strerror(err));
  }
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
