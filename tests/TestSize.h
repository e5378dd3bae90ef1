#pragma once
// The size of the sweeps, chosen by the test binary (tests/TestBinary.h) and overridden
// for one run by the environment variable MISALLOC_TEST_SIZE:
// * "full", the default: kernel = reference and the PTX test run a pairwise covering set
//   of their option space (tests/Covering.h), each statistical test the samples its
//   stated power needs (tests/Statistics.h, BiasFamily), and the sweeps run on the C++
//   reference, which kernel = reference proves equal to the kernel;
// * "small", the default of the sanitized tests (misalloc_tests_sanitized): a cheap
//   subset of each sweep's cases, every code path of it, the same assertions;
// * "exhaustive" (scripts/exhaustive-tests): the full products, and the sweeps on PoCL,
//   run before a change to the kernels lands (docs/testing.md).
#include <cstdlib>
#include <cstring>

#include "TestBinary.h"

namespace misalloc::test {

inline const char* testSizeName() {
  const char* size = std::getenv("MISALLOC_TEST_SIZE");
  return size == nullptr || *size == '\0' ? defaultTestSize() : size;
}

inline bool smallTestSize() { return std::strcmp(testSizeName(), "small") == 0; }
inline bool exhaustiveTestSize() { return std::strcmp(testSizeName(), "exhaustive") == 0; }

}  // namespace misalloc::test
