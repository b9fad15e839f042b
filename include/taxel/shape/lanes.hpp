// SPDX-License-Identifier: MIT
// The kernel sum at the heart of every posterior mean, sum_i w_i k(|x - x_i|) and its gradient,
// over several observations at once (lanes of a SIMD register). On x86-64 with GCC or Clang the
// sum runs four lanes wide with AVX2 and FMA when the CPU has them (checked once at run time),
// two lanes wide with SSE2 otherwise; elsewhere, or with TAXEL_NO_SIMD_DISPATCH defined, the
// process keeps its portable Eigen path. The lanes need an exponential without a division: e^x
// for x <= 0 by the usual reduction x = n ln 2 + t, |t| <= ln 2 / 2 (Cody and Waite), a degree-12
// Taylor polynomial for e^t (truncation below 2e-16 relative) and 2^n written into the exponent
// bits. Arguments below -700 are clamped there (e^-700 ~ 1e-304).
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

// The square roots below are the compilers' builtins behind _mm_sqrt_pd and _mm256_sqrt_pd
// (GCC's and Clang's alike): <immintrin.h> would add about half a second to every translation
// unit that includes taxel.
#if !defined(TAXEL_NO_SIMD_DISPATCH) && defined(__GNUC__) && defined(__x86_64__)
#define TAXEL_SHAPE_LANES 1
#else
#define TAXEL_SHAPE_LANES 0
#endif

#if TAXEL_SHAPE_LANES
namespace taxel::shape::detail::lanes {

using D2 = double __attribute__((vector_size(16)));
using D4 = double __attribute__((vector_size(32)));
using U2 = std::uint64_t __attribute__((vector_size(16)));
using U4 = std::uint64_t __attribute__((vector_size(32)));
template <class V>
struct Bits;
template <>
struct Bits<D2> {
  using type = U2;
  using int32 = std::int32_t __attribute__((vector_size(8)));
};
template <>
struct Bits<D4> {
  using type = U4;
  using int32 = std::int32_t __attribute__((vector_size(16)));
};

// Every helper takes and gives vectors by reference: a 32-byte vector passed by value in code
// compiled without AVX would change the calling convention (GCC's and Clang's -Wpsabi). They are
// always inlined into the functions below, which carry the instruction set.

template <class V>
[[gnu::always_inline]] inline void load(const double* p, V& v) {
  std::memcpy(&v, p, sizeof v);
}

template <class V>
[[gnu::always_inline]] inline double total(const V& v) {
  double s = 0.0;
  for (std::size_t i = 0; i < sizeof(V) / sizeof(double); ++i) s += v[i];
  return s;
}

/// e^x lane by lane for x <= 0 (see the file comment).
template <class V>
[[gnu::always_inline]] inline void exp_nonpositive(const V& x_in, V& out) {
  using U = typename Bits<V>::type;
  const V floor = V{} - 700.0;
  const U low = reinterpret_cast<U>(x_in < floor);  // all ones where x < -700
  const V x =
      reinterpret_cast<V>((reinterpret_cast<U>(x_in) & ~low) | (reinterpret_cast<U>(floor) & low));
  constexpr double log2e = 1.4426950408889634, ln2_hi = 0.693147180369123816490,
                   ln2_lo = 1.90821492927058770002e-10;
  // n = x / ln 2 rounded to the nearest integer (x <= 0: truncating x / ln 2 - 1/2), through
  // integer lanes: unlike adding and subtracting 1.5 * 2^52, -ffast-math cannot fold it away.
  using I32 = typename Bits<V>::int32;
  const I32 k = __builtin_convertvector(x * log2e - 0.5, I32);
  const V n = __builtin_convertvector(k, V);
  const V t = (x - n * ln2_hi) - n * ln2_lo;
  // 1/k! for k = 12 .. 0
  V p = V{} + 1.0 / 479001600.0;
  p = p * t + 1.0 / 39916800.0;
  p = p * t + 1.0 / 3628800.0;
  p = p * t + 1.0 / 362880.0;
  p = p * t + 1.0 / 40320.0;
  p = p * t + 1.0 / 5040.0;
  p = p * t + 1.0 / 720.0;
  p = p * t + 1.0 / 120.0;
  p = p * t + 1.0 / 24.0;
  p = p * t + 1.0 / 6.0;
  p = p * t + 0.5;
  p = p * t + 1.0;
  p = p * t + 1.0;
  // 2^n: n + 1023 in the low bits of a double's mantissa (n is an integer, so the sum is
  // exact), shifted into the exponent.
  const U two_n = reinterpret_cast<U>(n + (0x1p52 + 1023.0)) << 52;
  out = p * reinterpret_cast<V>(two_n);
}

/// Adds w k(r) to acc[0] and, with Gradient, w k'(r)/r (x - x_i) to acc[1..3].
template <bool Gradient, class K, class V>
[[gnu::always_inline]] inline void accumulate(const K& kernel, const V& dx, const V& dy,
                                              const V& dz, const V& r, const V& w, V* acc) {
  V k, slope;
  kernel.evaluate_lanes(r, k, slope);
  acc[0] += k * w;
  if constexpr (Gradient) {
    const V s = slope * w;
    acc[1] += s * dx;
    acc[2] += s * dy;
    acc[3] += s * dz;
  }
}

/// The observations left over after the last full group of lanes, one at a time.
template <bool Gradient, class K, class V>
[[gnu::always_inline]] inline double finish(const K& kernel, std::size_t i, std::size_t n,
                                            const double* const* p, const double* x,
                                            const double* w, double* gradient, const V* acc) {
  double out = total(acc[0]);
  double g[3] = {total(acc[1]), total(acc[2]), total(acc[3])};
  for (; i < n; ++i) {
    const double d[3] = {x[0] - p[0][i], x[1] - p[1][i], x[2] - p[2][i]};
    const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    out += w[i] * kernel(r);
    if constexpr (Gradient) {
      const double s = w[i] * kernel.slope(r);
      for (int j = 0; j < 3; ++j) g[j] += s * d[j];
    }
  }
  if constexpr (Gradient) {
    for (int j = 0; j < 3; ++j) gradient[j] = g[j];
  }
  return out;
}

/// sum_i w_i k(|x - p_i|) over n observations with coordinates p[0], p[1], p[2], and its gradient
/// (when Gradient) into gradient[0..2]: two lanes, SSE2.
template <bool Gradient, class K>
double kernel_sum_sse2(const K& kernel, std::size_t n, const double* const* p, const double* x,
                       const double* w, double* gradient) {
  D2 acc[4] = {};
  const D2 qx = D2{} + x[0], qy = D2{} + x[1], qz = D2{} + x[2];
  std::size_t i = 0;
  for (const std::size_t end = n - n % 2; i < end; i += 2) {
    D2 ox, oy, oz, wi;
    load(p[0] + i, ox);
    load(p[1] + i, oy);
    load(p[2] + i, oz);
    load(w + i, wi);
    const D2 dx = qx - ox, dy = qy - oy, dz = qz - oz;
    const D2 r = __builtin_ia32_sqrtpd(dx * dx + dy * dy + dz * dz);
    accumulate<Gradient>(kernel, dx, dy, dz, r, wi, acc);
  }
  return finish<Gradient>(kernel, i, n, p, x, w, gradient, acc);
}

/// The same four lanes wide, AVX2 and FMA: call only where cpu_has_avx2_fma().
template <bool Gradient, class K>
[[gnu::target("avx2,fma")]] double kernel_sum_avx2(const K& kernel, std::size_t n,
                                                   const double* const* p, const double* x,
                                                   const double* w, double* gradient) {
  D4 acc[4] = {};
  const D4 qx = D4{} + x[0], qy = D4{} + x[1], qz = D4{} + x[2];
  std::size_t i = 0;
  for (const std::size_t end = n - n % 4; i < end; i += 4) {
    D4 ox, oy, oz, wi;
    load(p[0] + i, ox);
    load(p[1] + i, oy);
    load(p[2] + i, oz);
    load(w + i, wi);
    const D4 dx = qx - ox, dy = qy - oy, dz = qz - oz;
    const D4 r = __builtin_ia32_sqrtpd256(dx * dx + dy * dy + dz * dz);
    accumulate<Gradient>(kernel, dx, dy, dz, r, wi, acc);
  }
  return finish<Gradient>(kernel, i, n, p, x, w, gradient, acc);
}

/// Whether this CPU runs AVX2 and FMA (asked once).
inline bool cpu_has_avx2_fma() {
#if defined(__AVX2__) && defined(__FMA__)
  return true;
#else
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  }();
  return yes;
#endif
}

/// A kernel that evaluates lanes: `evaluate_lanes(r, k, slope)` on vectors of distances.
template <class K>
concept LaneKernel = requires(const K& k, const D2& r, D2& out) {
  k.evaluate_lanes(r, out, out);
};

/// The kernel sum (see kernel_sum_sse2) on the widest lanes this CPU has.
template <bool Gradient, class K>
double kernel_sum(const K& kernel, std::size_t n, const double* const* p, const double* x,
                  const double* w, double* gradient) {
  if (cpu_has_avx2_fma()) return kernel_sum_avx2<Gradient>(kernel, n, p, x, w, gradient);
  return kernel_sum_sse2<Gradient>(kernel, n, p, x, w, gradient);
}

}  // namespace taxel::shape::detail::lanes
#endif
