#pragma once
#include <stdexcept>
#include <string>

namespace misalloc {

// A problem with what the user asked for or gave us (a missing file, a bad option):
// the CLI prints its message and exits non-zero without writing output.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The OpenCL layer failed: no platform, a build error (with its log), a failed call.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace misalloc
