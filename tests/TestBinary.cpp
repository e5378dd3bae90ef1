// What differs between the Release and the sanitized test binaries, which share every
// test file's object (tests/CMakeLists.txt): compiled into each with its own definitions.
#include "TestBinary.h"

namespace misalloc::test {

const char* misallocBinary() { return MISALLOC_BINARY; }
const char* defaultTestSize() { return MISALLOC_DEFAULT_TEST_SIZE; }

}  // namespace misalloc::test
