#pragma once
// The size of the sweeps, chosen by the build (-DMISALLOC_TEST_SIZE) and overridden for
// one run by the environment variable MISALLOC_TEST_SIZE:
// * "full", the default: kernel = reference, the statistical sweeps and the PTX test run
//   a pairwise covering set of their option space (tests/Covering.h), each statistical
//   test with the samples its stated power needs (tests/Statistics.h, BiasBound), and
//   the sweeps on the C++ reference, which kernel = reference proves equal to the kernel;
// * "small", the default of the sanitizer build (.ci/sanitized-tests): a cheap subset of
//   each sweep's cases, every code path of it, the same assertions;
// * "exhaustive" (scripts/exhaustive-tests): the full products, and the sweeps on PoCL,
//   run before a change to the kernels lands (docs/testing.md).
#include <cstdlib>
#include <cstring>

namespace misalloc::test {

#ifndef MISALLOC_DEFAULT_TEST_SIZE
#define MISALLOC_DEFAULT_TEST_SIZE "full"
#endif

inline const char* testSizeName() {
  const char* size = std::getenv("MISALLOC_TEST_SIZE");
  return size == nullptr || *size == '\0' ? MISALLOC_DEFAULT_TEST_SIZE : size;
}

inline bool smallTestSize() { return std::strcmp(testSizeName(), "small") == 0; }
inline bool exhaustiveTestSize() { return std::strcmp(testSizeName(), "exhaustive") == 0; }

}  // namespace misalloc::test
