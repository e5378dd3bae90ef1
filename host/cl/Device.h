#pragma once
#include <CL/opencl.hpp>
#include <cstdint>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

#include "Error.h"

namespace misalloc {

// One OpenCL device with its context and an in-order, profiling queue.
struct Device {
  cl::Platform platform;
  cl::Device device;
  cl::Context context;
  cl::CommandQueue queue;
  std::string part;  // a sub-device's place in its device, e.g. "sub-device 1/2"; else empty
  // A sub-device's whole device, in the same context; else null.
  std::shared_ptr<const Device> whole;
  // The programs built for it, by kernel file and options (buildProgram): a run that
  // builds many samplers (compare, the Python module's renders) builds each variant once.
  std::shared_ptr<std::map<std::string, cl::Program>> programs = std::make_shared<std::map<std::string, cl::Program>>();

  std::string name() const;
};

// Every device of every platform, in the order `misalloc devices` lists them.
std::vector<std::pair<cl::Platform, cl::Device>> enumerateDevices();

void listDevices(std::ostream& out);

// spec: "" or "auto" (the first GPU, else the first CPU), "cpu", "gpu", or an index
// into enumerateDevices(). Throws DeviceError with install advice if there is no
// OpenCL platform, InputError for a spec that matches nothing.
Device openDevice(const std::string& spec);

// Every OpenCL device (`--device all`).
std::vector<Device> openAllDevices();

// The device `spec` names (as openDevice) partitioned into `count` sub-devices of equal
// compute units (clCreateSubDevices, CL_DEVICE_PARTITION_EQUALLY), in one context,
// each with its own queue (`--device cpu:N`). Throws InputError where the device cannot.
std::vector<Device> openSubDevices(const std::string& spec, int count);

// The device time between a command's start and end (profiling events).
double eventSeconds(const cl::Event& event);

// A byte count in MiB, for the errors that give a device's limits.
std::string mebibytes(uint64_t bytes);

// An OpenCL error in words, with the option that caused it where it says so: for a
// buffer that `device` cannot hold, `cause` (the option that sized the buffers, for
// `pixels` pixels) and the device's limits; any other error by its code.
DeviceError explainBufferError(const cl::Error& e, const Device& device, const std::string& cause, int pixels);

// Builds `mainFile` (an embedded kernel source) with `options`, once per device; a
// failure throws DeviceError carrying the build log.
cl::Program buildProgram(const Device& device, const std::string& mainFile, const std::string& options);

}  // namespace misalloc
