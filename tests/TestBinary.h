#pragma once
// What differs between the Release and the sanitized test binaries (tests/TestBinary.cpp).

namespace misalloc::test {

// The misalloc program the CLI tests run: the sanitized one from the sanitized tests.
const char* misallocBinary();
// The test size without MISALLOC_TEST_SIZE (tests/TestSize.h): full, or small sanitized.
const char* defaultTestSize();

}  // namespace misalloc::test
