// SPDX-License-Identifier: MIT
// Deferred<T, D>: a type alias that postpones compiling a function body to its first use.
#pragma once

namespace taxel {

namespace detail {
template <class T, class D>
struct deferred {
  using type = T;
};
}  // namespace detail
/// `T`, spelled as a type that depends on `D`. A function template whose parameters (or local
/// types) are `Deferred<T, D>` with a defaulted `D` (`template <class D = void>`) is called like
/// a plain function, but the compiler checks and compiles its body only in the translation
/// units that call it: this header-only library's way to keep its Eigen-heavy code out of the
/// build of every file that merely includes it. Member functions that only need their body
/// compiled on use are plain `template <class = void>`.
template <class T, class D>
using Deferred = typename detail::deferred<T, D>::type;

}  // namespace taxel
