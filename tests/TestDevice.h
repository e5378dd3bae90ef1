#pragma once
// The OpenCL device the tests run on: PoCL's CPU device, opened once per process.
#include "cl/Device.h"

namespace misalloc::test {

inline const Device& testDevice() {
  static const Device device = openDevice("cpu");
  return device;
}

}  // namespace misalloc::test
