// SPDX-License-Identifier: MIT
// Shared command-line plumbing of the example tools: one-line errors with the tool's name and
// an exit code, option values, strictly parsed numbers and lengths with units, standard streams
// for "-", outputs that would replace an input refused (report.hpp: the results as text, JSON or
// CSV).
#pragma once

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <taxel/io/file.hpp>
#include <taxel/version.hpp>
#include <type_traits>
#include <utility>
#include <vector>

namespace taxel_cli {

/// vprintf into a string, appended whole however long the text.
[[gnu::format(printf, 2, 0)]] inline void vappendf(std::string& to, const char* fmt, va_list ap) {
  va_list again;
  va_copy(again, ap);
  const int n = std::vsnprintf(nullptr, 0, fmt, ap);
  if (n > 0) {
    const std::size_t at = to.size();
    to.resize(at + static_cast<std::size_t>(n) + 1);
    std::vsnprintf(to.data() + at, static_cast<std::size_t>(n) + 1, fmt, again);
    to.resize(at + static_cast<std::size_t>(n));
  }
  va_end(again);
}

/// printf into a string (the studies gather each job's lines and print them in a fixed order
/// afterwards).
[[gnu::format(printf, 2, 3)]] inline void appendf(std::string& to, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vappendf(to, fmt, ap);
  va_end(ap);
}

/// Makes a lost write to standard output an error, as a lost file write is: at exit (after
/// `return` from main or std::exit), flushes standard output and, when any write to it failed
/// (a full disk, /dev/full, a closed descriptor), prints "<tool>: cannot write standard output:
/// <reason>" and ends the process with exit code 1. Call once, first thing in main.
inline void check_stdout_at_exit(const char* tool) {
  static const char* name = "taxel";
  name = tool;
  std::atexit([] {
    errno = 0;
    if (std::fflush(stdout) != 0 || std::ferror(stdout) != 0) {
      const int err = errno;
      std::fprintf(stderr, "%s: cannot write standard output: %s\n", name,
                   err != 0 ? std::strerror(err) : "a write failed");
      std::_Exit(1);
    }
  });
}

/// Prints "<tool> (taxel) <version>" and exits 0 when any argument is `--version`.
inline void print_version_if_asked(const char* tool, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    if (std::string_view(argv[i]) == "--version") {
      std::printf("%s (taxel) %s\n", tool, TAXEL_VERSION_STRING);
      std::exit(0);
    }
  }
}

/// The largest side of the bounding box of `points` (anything with .x() .y() .z()); 0 when
/// there are none. Non-finite points are skipped.
template <class Points>
double largest_extent(const Points& points) {
  double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
  for (const auto& p : points) {
    const double v[3] = {double(p.x()), double(p.y()), double(p.z())};
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) continue;
    for (int a = 0; a < 3; ++a) {
      lo[a] = v[a] < lo[a] ? v[a] : lo[a];
      hi[a] = v[a] > hi[a] ? v[a] : hi[a];
    }
  }
  double e = 0.0;
  for (int a = 0; a < 3; ++a) e = hi[a] - lo[a] > e ? hi[a] - lo[a] : e;
  return e;
}

/// Tactile objects are centimetres across and taxel works in metres: coordinates spanning more
/// than `limit` (1 m), up to 10 km, look like millimetres. Prints "<tool>: warning: <what> spans
/// <e> along one axis: its coordinates look like millimetres; taxel uses metres: --scale 0.001" and
/// returns true when they do.
inline bool warn_if_millimetres(const char* tool, const std::string& what, double extent,
                                double limit = 1.0) {
  if (!(extent > limit) || !(extent <= 1e4 * limit)) return false;  // larger is not millimetres
  std::fprintf(stderr,
               "%s: warning: %s spans %.4g along one axis: its coordinates look like "
               "millimetres; taxel uses metres: --scale 0.001\n",
               tool, what.c_str(), extent);
  return true;
}

/// Parses a finite length into `metres`: a number in metres ("0.004") or a number with a unit,
/// m, cm, mm, um or µm ("4mm", "0.4 cm"). False when `text` is neither.
inline bool parse_length(std::string_view text, double& metres) {
  double v = 0;
  const char* end = text.data() + text.size();
  const auto res = std::from_chars(text.data(), end, v);
  if (res.ec != std::errc() || !std::isfinite(v)) return false;
  std::string_view unit(res.ptr, static_cast<std::size_t>(end - res.ptr));
  while (!unit.empty() && unit.front() == ' ') unit.remove_prefix(1);
  if (unit == "cm") {
    v *= 1e-2;
  } else if (unit == "mm") {
    v *= 1e-3;
  } else if (unit == "um" || unit == "\u00b5m" || unit == "\u03bcm") {
    v *= 1e-6;
  } else if (!unit.empty() && unit != "m") {
    return false;
  }
  metres = v;
  return true;
}

/// The device and inode of the file a tool's argument opens, when it is a regular file: "-"
/// is the standard stream `std_fd` (0 for an input, 1 for an output); a path is followed
/// through symbolic links, so /dev/stdin, /dev/fd/0 and /proc/self/fd/0 are the file the
/// shell redirected. Nothing for a missing file, a pipe, a terminal or a device.
inline std::optional<std::pair<dev_t, ino_t>> regular_file_id(std::string_view path, int std_fd) {
  struct ::stat st {};
  const int rc = path == "-" ? ::fstat(std_fd, &st) : ::stat(std::string(path).c_str(), &st);
  if (rc != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  return std::pair{st.st_dev, st.st_ino};
}

/// True when the arguments `a` and `b` name the same file: the same regular file opened (hard
/// or symbolic links, /dev/stdin, and "-" as the standard stream `a_fd` or `b_fd` included),
/// or the same path once made absolute and resolved ("./x" and "x", for outputs that do not
/// exist yet). Empty names are no files.
inline bool same_file(std::string_view a, std::string_view b, int a_fd = 0, int b_fd = 0) {
  if (a.empty() || b.empty()) return false;
  const auto ia = regular_file_id(a, a_fd), ib = regular_file_id(b, b_fd);
  if (ia && ib) return *ia == *ib;
  if (a == "-" || b == "-") return false;
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path pa(a), pb(b);
  if (fs::equivalent(pa, pb, ec)) return true;
  const fs::path ca = fs::weakly_canonical(pa, ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(pb, ec);
  return !ec && ca == cb;
}

/// Why the output `output` cannot be written, or "" when it can: it is one of `inputs` or of
/// `other_outputs` (same_file; "-" is standard input among the inputs and standard output among the
/// outputs). A tool writes its outputs after reading its inputs, so it would replace an input with
/// its result, or one output with another.
template <class Inputs = std::initializer_list<std::string_view>>
std::string output_conflict(std::string_view output, const Inputs& inputs,
                            std::initializer_list<std::string_view> other_outputs = {}) {
  for (const auto& in : inputs) {
    if (same_file(output, in, 1, 0)) {
      return "the output '" + std::string(output) + "' is the input '" +
             std::string(in == "-" ? "<stdin>" : in) +
             "': writing it would replace the input; name another output";
    }
  }
  for (const std::string_view other : other_outputs) {
    if (!other.empty() && other != "-" && output != "-" && same_file(output, other, 1, 1)) {
      return "the outputs '" + std::string(output) + "' and '" + std::string(other) +
             "' are the same file; name two different files";
    }
  }
  return {};
}

/// Walks argv. Errors print "<tool>: <why>" on one line and exit (2 by default: bad usage).
class Args {
 public:
  Args(const char* tool, int argc, char** argv) : tool_(tool), argc_(argc), argv_(argv) {}

  /// The next argument, or false at the end. `--name=value` comes back as `--name`, its value
  /// kept for value(); an option that takes no value fails when given one.
  bool next(std::string_view& arg) {
    if (inline_value_) fail(std::string(current_) + " takes no value");
    if (i_ + 1 >= argc_) return false;
    arg = current_ = argv_[++i_];
    if (arg.empty()) fail("argument " + std::to_string(i_) + " is empty: name a file");
    if (arg.size() > 2 && arg.substr(0, 2) == "--") {
      if (const auto eq = arg.find('='); eq != std::string_view::npos) {
        inline_value_ = arg.substr(eq + 1);
        arg = current_ = arg.substr(0, eq);
      }
    }
    return true;
  }

  /// The value of the current option (after '=', or the next argument); fails when there is
  /// none or it is empty (every value is a file name, a number or a word).
  std::string_view value() {
    const std::string_view v = next_value();
    if (v.empty()) fail(std::string(current_) + " needs a value, not an empty string");
    return v;
  }

  /// The current option's value as a number of type T in [lo, hi].
  template <class T>
  T number(T lo, T hi) {
    const std::string_view text = value();
    T v{};
    const auto res = std::from_chars(text.data(), text.data() + text.size(), v);
    if (res.ec != std::errc() || res.ptr != text.data() + text.size() || !(v >= lo && v <= hi)) {
      fail(std::string(current_) + ": '" + std::string(text) + "' is not " + range(lo, hi));
    }
    return v;
  }

  /// The current option's value as a length in metres within [lo, hi] metres: a number in
  /// metres ("0.004"), or a number with a unit: m, cm, mm, um or µm ("4mm", "0.4 cm").
  double length(double lo, double hi) {
    const std::string_view text = value();
    double v = 0;
    if (!parse_length(text, v) || !(v >= lo && v <= hi)) {
      fail(std::string(current_) + ": '" + std::string(text) +
           "' is not a length (metres, or a number with a unit m, cm, mm or um: 4mm, 0.004)" +
           (std::isinf(lo) && std::isinf(hi) ? std::string() : " in " + bounds(lo, hi) + " m"));
    }
    return v;
  }

  /// The current option's value as an output format among `allowed` (e.g. "text|json|csv").
  std::string_view choice(std::string_view allowed) {
    const std::string_view v = value();
    for (std::size_t pos = 0; pos <= allowed.size();) {
      const std::size_t bar = std::min(allowed.find('|', pos), allowed.size());
      if (allowed.substr(pos, bar - pos) == v) return v;
      pos = bar + 1;
    }
    std::string list(allowed);
    for (char& c : list) c = c == '|' ? ',' : c;
    fail(std::string(current_) + " must be one of " + list + ", not '" + std::string(v) + "'");
  }

  /// Fails (exit 2) with output_conflict's message when there is one.
  void check_output(std::string_view output, std::initializer_list<std::string_view> inputs,
                    std::initializer_list<std::string_view> other_outputs = {}) const {
    const std::string why = output_conflict(output, inputs, other_outputs);
    if (!why.empty()) fail(why);
  }

  /// Prints "<tool>: <why>" and exits with `code`.
  [[noreturn]] void fail(const std::string& why, int code = 2) const {
    std::fprintf(stderr, "%s: %s\n", tool_, why.c_str());
    std::exit(code);
  }

 private:
  std::string_view next_value() {
    if (inline_value_) {
      const std::string_view v = *inline_value_;
      inline_value_.reset();
      return v;
    }
    if (i_ + 1 >= argc_) fail(std::string(current_) + " needs a value");
    return argv_[++i_];
  }
  template <class T>
  static std::string range(T lo, T hi) {
    if constexpr (std::is_floating_point_v<T>) {
      if (std::isinf(lo) && std::isinf(hi)) return "a finite number";
    }
    return "a number in " + bounds(lo, hi);
  }
  template <class T>
  static std::string bounds(T lo, T hi) {
    const auto one = [](T v) {
      if constexpr (std::is_floating_point_v<T>) {
        if (std::isinf(v)) return std::string(v < 0 ? "-inf" : "inf");
        char buf[32];
        std::snprintf(buf, sizeof buf, "%g", static_cast<double>(v));
        return std::string(buf);
      } else {
        return std::to_string(v);
      }
    };
    // The least positive double as a lower bound reads as an open interval from 0.
    const bool open = std::is_floating_point_v<T> && lo == std::numeric_limits<T>::min();
    std::string out = open ? "(0" : "[" + one(lo);
    out.append(", ").append(one(hi)).append("]");
    return out;
  }

  const char* tool_;
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string_view current_;
  std::optional<std::string_view> inline_value_;  // from --name=value, until value() takes it
};

/// The options every study example takes: --quick, --out DIR, -h/--help (which prints `usage`
/// and exits). `extra(arg, args)` may claim further options by returning true.
struct StudyOptions {
  bool quick = false;
  std::string out;
};
template <class Extra>
StudyOptions parse_study_options(const char* tool, const char* usage, std::string default_out,
                                 int argc, char** argv, Extra extra) {
  Args args(tool, argc, argv);
  StudyOptions o{false, std::move(default_out)};
  std::string_view a;
  while (args.next(a)) {
    if (a == "--quick") {
      o.quick = true;
    } else if (a == "--out") {
      o.out = std::string(args.value());
    } else if (a == "-h" || a == "--help") {
      std::fputs(usage, stdout);
      std::exit(0);
    } else if (!extra(a, args)) {
      args.fail("unknown argument '" + std::string(a) + "' (see --help)");
    }
  }
  return o;
}
inline StudyOptions parse_study_options(const char* tool, const char* usage,
                                        std::string default_out, int argc, char** argv) {
  return parse_study_options(tool, usage, std::move(default_out), argc, argv,
                             [](std::string_view, Args&) { return false; });
}

/// The bytes of the input `path`: standard input when `path` is "-". Throws taxel::IoError.
inline std::string read_input(const std::string& path) {
  return taxel::io::read_file(path == "-" ? "/dev/stdin" : path);
}

/// The name of an input in messages: "<stdin>" for "-".
inline std::string input_name(const std::string& path) { return path == "-" ? "<stdin>" : path; }

/// Writes `bytes` to the output `path`, whole or not at all (taxel::io::write_file), or to
/// standard output when `path` is "-" (a lost write there is caught at exit).
inline void write_output(const std::string& path, std::string_view bytes) {
  if (path == "-") {
    std::fwrite(bytes.data(), 1, bytes.size(), stdout);
  } else {
    taxel::io::write_file(path, bytes);
  }
}

/// Writes outputs that belong together as a set (taxel::io::write_files): every file is
/// written before any replaces its previous version, so a failure leaves all of them as they
/// were. An output "-" goes to standard output after the files are in place.
inline void write_outputs(const std::vector<std::pair<std::string, std::string>>& outputs) {
  std::vector<taxel::io::FileContent> files;
  for (const auto& [path, bytes] : outputs) {
    if (path != "-") files.push_back({path, bytes});
  }
  taxel::io::write_files(files);
  for (const auto& [path, bytes] : outputs) {
    if (path == "-") write_output(path, bytes);
  }
}

/// `s` with quotes and backslashes escaped and control characters blanked, for JSON strings.
inline std::string json_escape(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(static_cast<unsigned char>(c) < 0x20 ? ' ' : c);
  }
  return out;
}

}  // namespace taxel_cli
