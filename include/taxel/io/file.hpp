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
#include <vector>

#include "taxel/core/error.hpp"

namespace taxel::io {

/// Splits text into lines ending in LF, CRLF or a lone CR (the line ending is not part of a
/// line) and counts them from 1; the last line may lack its ending. A UTF-8 byte-order mark at
/// the start is skipped (spreadsheet programs write one). The text readers share it.
class LineReader {
 public:
  /// Reads `text`, which must outlive the reader.
  explicit LineReader(std::string_view text) noexcept : text_(text) {
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;
  }

  /// The next line; false once the text is used up.
  bool next(std::string_view& line) noexcept {
    if (pos_ >= text_.size()) return false;
    // memchr twice per line rather than one scan for either byte: the common LF and CRLF
    // endings stay on the fast path.
    const std::size_t nl = text_.find('\n', pos_);
    const std::size_t lf = nl == std::string_view::npos ? text_.size() : nl;
    std::size_t end = lf, after = nl == std::string_view::npos ? lf : lf + 1;
    if (const void* cr = std::memchr(text_.data() + pos_, '\r', lf - pos_)) {
      end = static_cast<std::size_t>(static_cast<const char*>(cr) - text_.data());
      if (end + 1 != lf) after = end + 1;  // a lone CR (classic Mac OS) ends the line
    }
    line = text_.substr(pos_, end - pos_);
    pos_ = after;
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

/// Reads a file (or a pipe, or standard input as /dev/stdin) line by line in blocks of 1 MiB,
/// with LineReader's rules (LF, CRLF or a lone CR; a leading byte-order mark skipped), so that a
/// large text input is read in memory independent of its size. A line longer than
/// `max_line_bytes` (64 MiB) is refused. Throws IoError naming the file.
class FileLineReader {
 public:
  static constexpr std::size_t kBlockBytes = std::size_t{1}
                                             << 20;  ///< Bytes read from the file at a time.

  /// Opens `path`; `source` names it in messages (default: the path).
  explicit FileLineReader(const std::string& path, std::string source = {},
                          std::size_t max_line_bytes = std::size_t{1} << 26)
      : source_(source.empty() ? path : std::move(source)), max_line_(max_line_bytes) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0)
      throw IoError(source_, std::string("cannot open for reading: ") + std::strerror(errno));
    struct ::stat st {};
    if (::fstat(fd_, &st) != 0 || S_ISDIR(st.st_mode)) {
      const int err = errno;
      ::close(fd_);
      throw IoError(source_, S_ISDIR(st.st_mode)
                                 ? std::string("is a folder, not a file")
                                 : std::string("cannot stat: ") + std::strerror(err));
    }
  }
  FileLineReader(const FileLineReader&) = delete;
  FileLineReader& operator=(const FileLineReader&) = delete;
  ~FileLineReader() { ::close(fd_); }

  /// The next line, valid until the next call; false at the end of the file.
  bool next(std::string_view& line) {
    for (;;) {
      const std::string_view rest = std::string_view(buf_).substr(pos_);
      const std::size_t end = rest.find_first_of("\r\n");
      // A CR at the end of the block may be the first half of a CRLF: read on to see.
      if (end != std::string_view::npos && (rest[end] == '\n' || end + 1 < rest.size() || eof_)) {
        line = rest.substr(0, end);
        pos_ += end + (rest[end] == '\r' && end + 1 < rest.size() && rest[end + 1] == '\n' ? 2 : 1);
        return counted(line);
      }
      if (eof_) {
        if (rest.empty()) return false;
        line = rest;
        pos_ = buf_.size();
        return counted(line);
      }
      buf_.erase(0, pos_);
      pos_ = 0;
      if (buf_.size() > max_line_) {
        throw IoError(source_, "a line is longer than " + std::to_string(max_line_) + " bytes",
                      number_ + 1);
      }
      fill();
    }
  }
  /// Number of the line `next` returned last (0 before the first).
  [[nodiscard]] std::uint64_t line_number() const noexcept { return number_; }
  /// Bytes read from the file so far.
  [[nodiscard]] std::uint64_t bytes_read() const noexcept { return bytes_; }

 private:
  bool counted(std::string_view& line) noexcept {
    if (number_++ == 0 && line.substr(0, 3) == "\xEF\xBB\xBF") line.remove_prefix(3);
    return true;
  }
  void fill() {
    const std::size_t at = buf_.size();
    buf_.resize(at + kBlockBytes);
    ::ssize_t n = 0;
    do {
      n = ::read(fd_, buf_.data() + at, kBlockBytes);
    } while (n < 0 && errno == EINTR);
    if (n < 0) {
      const int err = errno;
      buf_.resize(at);
      throw IoError(source_, std::string("read failed: ") + std::strerror(err));
    }
    buf_.resize(at + static_cast<std::size_t>(n));
    bytes_ += static_cast<std::uint64_t>(n);
    eof_ = n == 0;
  }

  std::string source_;
  std::size_t max_line_;
  int fd_ = -1;
  std::string buf_;
  std::size_t pos_ = 0;
  std::uint64_t number_ = 0, bytes_ = 0;
  bool eof_ = false;
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

namespace detail {

/// One output of write_files between its two phases: written to `tmp` (a regular file's
/// temporary beside `target`), or to be written in place (a device or a pipe).
struct PendingWrite {
  std::string path, target, tmp;
  std::string_view bytes;
  bool in_place = false;
};

/// First phase: checks `path` and writes `bytes` to a flushed temporary file beside it (a
/// regular file or a new one), or marks it for writing in place (a device or a pipe: there is
/// nothing to replace). Throws IoError; leaves nothing behind on failure.
inline PendingWrite stage_write(const std::string& path, std::string_view bytes) {
  if (path.empty()) throw IoError(path, "cannot write: the file name is empty");
  PendingWrite w{path, path, {}, bytes, false};
  struct ::stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw IoError(path, "cannot write: it is a folder");
  if (exists && !S_ISREG(st.st_mode)) {
    w.in_place = true;
    return w;
  }
  struct ::stat lst {};
  if (exists && ::lstat(path.c_str(), &lst) == 0 && S_ISLNK(lst.st_mode)) {
    if (char* real = ::realpath(path.c_str(), nullptr)) {
      w.target = real;
      std::free(real);
    }
  }
  w.tmp = temporary_beside(w.target);
  // 0666 minus the umask, as a plain open would; an existing file keeps its permissions.
  const int fd = ::open(w.tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0)
    throw IoError(path, std::string("cannot create a file beside it: ") + std::strerror(errno));
  int err = write_all(fd, bytes);
  if (err == 0 && exists) (void)::fchmod(fd, st.st_mode & 07777);
  if (err == 0 && ::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) {
    ::unlink(w.tmp.c_str());
    throw IoError(path, std::string("write failed (the previous file, if any, is unchanged): ") +
                            std::strerror(err));
  }
  return w;
}

/// Second phase: renames the temporary over the target, or writes a device in place.
inline void commit_write(const PendingWrite& w) {
  if (w.in_place) {
    const int fd = ::open(w.path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
    if (fd < 0)
      throw IoError(w.path, std::string("cannot open for writing: ") + std::strerror(errno));
    int err = write_all(fd, w.bytes);
    if (::close(fd) != 0 && err == 0) err = errno;
    if (err != 0) throw IoError(w.path, std::string("write failed: ") + std::strerror(err));
    return;
  }
  if (::rename(w.tmp.c_str(), w.target.c_str()) != 0) {
    const int err = errno;
    ::unlink(w.tmp.c_str());
    throw IoError(w.path, std::string("write failed (the previous file, if any, is unchanged): ") +
                              std::strerror(err));
  }
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
  detail::commit_write(detail::stage_write(path, bytes));
}

/// One file of a set written by write_files.
struct FileContent {
  std::string path;        ///< where it goes
  std::string_view bytes;  ///< what it holds
};

/// Writes files that belong together (readings and their poses, a cloud and its truth) as a
/// set: each is written to a flushed temporary file beside its target first, and only when all
/// of them are written are they renamed into place. A failure while writing (a full disk, a
/// folder that cannot be written) removes the temporaries and leaves every previous file as it
/// was, so that a new file never sits beside an old partner. Devices and pipes are written
/// last, in place. Throws IoError naming the file that failed.
inline void write_files(const std::vector<FileContent>& files) {
  std::vector<detail::PendingWrite> staged;
  staged.reserve(files.size());
  try {
    for (const FileContent& f : files) staged.push_back(detail::stage_write(f.path, f.bytes));
  } catch (...) {
    for (const auto& w : staged) {
      if (!w.in_place) ::unlink(w.tmp.c_str());
    }
    throw;
  }
  // Renames cannot fail for want of space; a rename refused half-way (the folder turned
  // read-only meanwhile) is reported, and the later temporaries are removed.
  for (std::size_t i = 0; i < staged.size(); ++i) {
    if (staged[i].in_place) continue;
    try {
      detail::commit_write(staged[i]);
    } catch (...) {
      for (std::size_t j = i + 1; j < staged.size(); ++j) {
        if (!staged[j].in_place) ::unlink(staged[j].tmp.c_str());
      }
      throw;
    }
  }
  for (const auto& w : staged) {
    if (w.in_place) detail::commit_write(w);
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
