// SPDX-License-Identifier: MIT
// Counts heap allocations so a test can prove a code path allocates nothing. AddressSanitizer
// owns operator new itself, so counting is off there and tests skip their checks
// (TAXEL_TEST_COUNTS_ALLOCATIONS == 0).
#pragma once

#include <atomic>

// GCC says so by __SANITIZE_ADDRESS__, clang (before 17) only by __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define TAXEL_TEST_COUNTS_ALLOCATIONS 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define TAXEL_TEST_COUNTS_ALLOCATIONS 0
#endif
#endif
#ifndef TAXEL_TEST_COUNTS_ALLOCATIONS
#define TAXEL_TEST_COUNTS_ALLOCATIONS 1
#endif

namespace taxel_test {
/// Number of calls to the global operator new so far (0 forever under ASan).
extern std::atomic<long> g_allocations;
}  // namespace taxel_test
