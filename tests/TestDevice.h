#pragma once
// The OpenCL device the tests run on: PoCL's CPU device, opened once per process.
// MISALLOC_TEST_DEVICE takes any `--device` choice (`gpu`, an index) so that the same
// tests check a GPU driver where one is present; CI has none.
#include <cstdlib>

#include "cl/Device.h"

namespace misalloc::test {

inline const Device& testDevice() {
  static const Device device = [] {
    const char* spec = std::getenv("MISALLOC_TEST_DEVICE");
    return openDevice(spec != nullptr && *spec != '\0' ? spec : "cpu");
  }();
  return device;
}

}  // namespace misalloc::test
