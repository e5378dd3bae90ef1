#pragma once
// The size of the statistical sweeps: "full" runs every case, "small" a cheap subset
// of the cases (fewer parameter combinations or samples, every code path of the sweep,
// the same assertions). The build chooses with -DMISALLOC_TEST_SIZE: full by default,
// small in the sanitizer build (-DMISALLOC_SANITIZE=ON, .ci/sanitized-tests), where the
// full sweeps would cost many minutes under ASan+UBSan; the Release run of ctest keeps
// the full sweeps. The environment variable MISALLOC_TEST_SIZE overrides the build's
// choice for one run.
#include <cstdlib>
#include <cstring>

namespace misalloc::test {

#ifndef MISALLOC_DEFAULT_TEST_SIZE
#define MISALLOC_DEFAULT_TEST_SIZE "full"
#endif

inline bool smallTestSize() {
  const char* size = std::getenv("MISALLOC_TEST_SIZE");
  if (size == nullptr || *size == '\0') size = MISALLOC_DEFAULT_TEST_SIZE;
  return std::strcmp(size, "small") == 0;
}

}  // namespace misalloc::test
