// SPDX-License-Identifier: MIT
// Any of taxel's classifiers (LinearSvm, Knn, Lda, RbfSvm, Mlp), with its options and what it
// learned, as bytes and back: the state behind Python's pickling and save/load. LinearSvm also
// reads and writes LIBLINEAR's text model files (LinearSvm::save / load); this form keeps every
// option and the training record too, and suits every classifier.
//
// The bytes, little-endian (taxel/io/binary.hpp):
//   magic    6 bytes "TXLRN" 0x00
//   version  uint8, 1
//   kind     uint8 length, then the class name ("LinearSvm", "Knn", "Lda", "RbfSvm", "Mlp")
//   state    the class's fields in the order its state() visits them: arithmetic values as
//            themselves (bool and enumerations as uint8), vectors as a uint64 count and the
//            values, matrices as uint64 rows and cols and the values row by row
// Reading refuses another magic, version or kind, bytes cut short or left over, counts beyond
// the bytes, values not finite, options out of range and parts whose sizes disagree.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "taxel/io/binary.hpp"
#include "taxel/learn/knn.hpp"
#include "taxel/learn/lda.hpp"
#include "taxel/learn/linear_svm.hpp"
#include "taxel/learn/mlp.hpp"
#include "taxel/learn/rbf_svm.hpp"

namespace taxel::learn {

namespace detail {

inline constexpr char kModelMagic[6] = {'T', 'X', 'L', 'R', 'N', 0};
inline constexpr std::uint8_t kModelVersion = 1;

template <class C>
constexpr const char* model_kind() {
  if constexpr (std::is_same_v<C, LinearSvm>) return "LinearSvm";
  if constexpr (std::is_same_v<C, Knn>) return "Knn";
  if constexpr (std::is_same_v<C, Lda>) return "Lda";
  if constexpr (std::is_same_v<C, RbfSvm>) return "RbfSvm";
  if constexpr (std::is_same_v<C, Mlp>) return "Mlp";
}

/// The archive a classifier's state() writes through.
struct StateWriter {
  io::BinaryWriter w;
  template <class T>
  void value(T& v, const char*) {
    if constexpr (std::is_enum_v<T> || std::is_same_v<T, bool>) {
      w.put<std::uint8_t>(static_cast<std::uint8_t>(v));
    } else {
      w.put<T>(v);
    }
  }
  template <class E>
  void enumeration(E& e, int, const char* what) {
    value(e, what);
  }
  template <class T>
  void vector(std::vector<T>& v, const char*) {
    w.put_vector(v);
  }
  void pairs(std::vector<std::pair<int, double>>& v, const char*) {
    w.put<std::uint64_t>(v.size());
    for (const auto& [k, x] : v) {
      w.put<std::int32_t>(k);
      w.put<double>(x);
    }
  }
  void text(std::string& s, const char*) {
    w.put<std::uint64_t>(s.size());
    w.out += s;
  }
  template <class M>
  void matrix(M& m, const char*) {
    w.put_matrix(m);
  }
  template <class M>
  void matrices(std::vector<M>& ms, const char*) {
    w.put<std::uint64_t>(ms.size());
    for (const M& m : ms) w.put_matrix(m);
  }
  template <class V>
  void nested(std::vector<std::vector<V>>& vs, const char*) {
    w.put<std::uint64_t>(vs.size());
    for (const auto& v : vs) w.put_vector(v);
  }
  template <class F>
  void verify(F&&) {}
};

/// The archive a classifier's state() reads through.
struct StateReader {
  io::BinaryReader r;
  template <class T>
  void value(T& v, const char* what) {
    if constexpr (std::is_same_v<T, bool>) {
      const auto b = r.get<std::uint8_t>(what);
      if (b > 1) r.fail(std::string(what) + " is not 0 or 1");
      v = b != 0;
    } else if constexpr (std::is_floating_point_v<T>) {
      v = static_cast<T>(r.finite(what));
    } else {
      v = r.get<T>(what);
    }
  }
  template <class E>
  void enumeration(E& e, int values, const char* what) {
    const auto b = r.get<std::uint8_t>(what);
    if (b >= values) r.fail(std::string(what) + ": unknown value " + std::to_string(int(b)));
    e = static_cast<E>(b);
  }
  template <class T>
  void vector(std::vector<T>& v, const char* what) {
    v = r.get_vector<T>(what);
  }
  void pairs(std::vector<std::pair<int, double>>& v, const char* what) {
    v.resize(r.count(what, 12));
    for (auto& [k, x] : v) {
      k = r.get<std::int32_t>(what);
      x = r.finite(what);
    }
  }
  void text(std::string& s, const char* what) {
    const std::size_t n = r.count(what, 1);
    s.assign(r.bytes.substr(r.at, n));
    r.at += n;
  }
  template <class M>
  void matrix(M& m, const char* what) {
    r.get_matrix(m, what);
  }
  template <class M>
  void matrices(std::vector<M>& ms, const char* what) {
    ms.resize(r.count(what, 16));
    for (M& m : ms) r.get_matrix(m, what);
  }
  template <class V>
  void nested(std::vector<std::vector<V>>& vs, const char* what) {
    vs.resize(r.count(what, 8));
    for (auto& v : vs) v = r.get_vector<V>(what);
  }
  // `check` returns "" when the state read so far is consistent, else what is wrong.
  template <class F>
  void verify(F&& check) {
    std::string problem;
    try {
      problem = check();
    } catch (const std::invalid_argument& e) {
      problem = e.what();
    }
    if (!problem.empty()) r.fail(problem);
  }
};

}  // namespace detail

/// A classifier as bytes (see the file comment): its options, its classes and what it learned,
/// fitted or not.
template <class C>
std::string encode_model(const C& model) {
  detail::StateWriter out;
  out.w.out.assign(detail::kModelMagic, sizeof detail::kModelMagic);
  out.w.put<std::uint8_t>(detail::kModelVersion);
  const std::string_view kind = detail::model_kind<C>();
  out.w.put<std::uint8_t>(static_cast<std::uint8_t>(kind.size()));
  out.w.out += kind;
  // state() visits the members to read or write them; writing leaves them as they are.
  const_cast<C&>(model).state(out);
  return std::move(out.w.out);
}

/// The kind of classifier some bytes of encode_model hold ("LinearSvm", ...); `source` names
/// them in errors. Throws IoError when they are not such bytes.
template <class = void>
std::string model_kind(std::string_view bytes, const std::string& source = "<model>") {
  if (bytes.size() < 8 || std::memcmp(bytes.data(), detail::kModelMagic, 6) != 0) {
    throw IoError(source, "not a taxel model (no TXLRN header)");
  }
  if (static_cast<std::uint8_t>(bytes[6]) != detail::kModelVersion) {
    throw IoError(source, "model format version " +
                              std::to_string(static_cast<std::uint8_t>(bytes[6])) +
                              " is not supported (this taxel reads version 1)");
  }
  const auto n = static_cast<std::uint8_t>(bytes[7]);
  if (bytes.size() - 8 < n) throw IoError(source, "cut short in the model's kind");
  return std::string(bytes.substr(8, n));
}

/// The classifier of type C from bytes of encode_model. Throws IoError for another kind of
/// classifier and for damaged bytes (see the file comment).
template <class C>
C decode_model(std::string_view bytes, const std::string& source = "<model>") {
  const std::string kind = model_kind(bytes, source);
  if (kind != detail::model_kind<C>()) {
    throw IoError(source, "holds a " + kind + ", not a " + detail::model_kind<C>());
  }
  detail::StateReader in{io::BinaryReader{bytes, source, 8 + kind.size()}};
  C model;
  model.state(in);
  if (!in.r.done()) in.r.fail("bytes left over after the model");
  return model;
}

}  // namespace taxel::learn
