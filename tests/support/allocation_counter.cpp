// SPDX-License-Identifier: MIT
#include "support/allocation_counter.hpp"

#include <cstdlib>
#include <new>

namespace taxel_test {
std::atomic<long> g_allocations{0};
}  // namespace taxel_test

#if TAXEL_TEST_COUNTS_ALLOCATIONS
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
void* operator new(std::size_t n) {
  ++taxel_test::g_allocations;
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
#endif
