#include "cl/Device.h"

#include <fmt/format.h>

#include <algorithm>

#include "Error.h"
#include "cl/KernelSource.h"

namespace misalloc {
namespace {

const char* kInstallAdvice =
    "no OpenCL platform found. Install PoCL (a CPU OpenCL driver) and the ICD loader: "
    "`sudo apt-get install pocl-opencl-icd ocl-icd-libopencl1` (Debian/Ubuntu), or a GPU vendor's OpenCL driver";

std::vector<cl::Platform> platforms() {
  std::vector<cl::Platform> list;
  // The ICD loader reports "no platform" as an error code, not as an empty list.
  cl_uint count = 0;
  if (clGetPlatformIDs(0, nullptr, &count) != CL_SUCCESS || count == 0) return list;
  cl::Platform::get(&list);
  return list;
}

bool hasType(const cl::Device& d, cl_device_type type) { return (d.getInfo<CL_DEVICE_TYPE>() & type) != 0; }

}  // namespace

std::string Device::name() const {
  return fmt::format("{} ({})", device.getInfo<CL_DEVICE_NAME>(), platform.getInfo<CL_PLATFORM_NAME>());
}

std::vector<std::pair<cl::Platform, cl::Device>> enumerateDevices() {
  std::vector<std::pair<cl::Platform, cl::Device>> all;
  for (const auto& p : platforms()) {
    std::vector<cl::Device> devices;
    if (p.getDevices(CL_DEVICE_TYPE_ALL, &devices) != CL_SUCCESS) continue;
    for (const auto& d : devices) all.emplace_back(p, d);
  }
  return all;
}

void listDevices(std::ostream& out) {
  auto all = enumerateDevices();
  if (all.empty()) throw DeviceError(kInstallAdvice);
  for (size_t i = 0; i < all.size(); ++i) {
    const auto& [p, d] = all[i];
    out << fmt::format("[{}] {} | {} | {} | {} compute units | {} MiB | {}\n", i, p.getInfo<CL_PLATFORM_NAME>(),
                       d.getInfo<CL_DEVICE_NAME>(), hasType(d, CL_DEVICE_TYPE_GPU) ? "gpu" : "cpu",
                       d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>(), d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>() >> 20,
                       d.getInfo<CL_DEVICE_VERSION>());
  }
}

Device openDevice(const std::string& spec) {
  auto all = enumerateDevices();
  if (all.empty()) throw DeviceError(kInstallAdvice);
  auto pickType = [&](cl_device_type type) {
    return std::find_if(all.begin(), all.end(), [&](const auto& pd) { return hasType(pd.second, type); });
  };
  auto it = all.end();
  if (spec.empty() || spec == "auto") {
    it = pickType(CL_DEVICE_TYPE_GPU);
    if (it == all.end()) it = pickType(CL_DEVICE_TYPE_CPU);
    if (it == all.end()) it = all.begin();
  } else if (spec == "gpu" || spec == "cpu") {
    it = pickType(spec == "gpu" ? CL_DEVICE_TYPE_GPU : CL_DEVICE_TYPE_CPU);
    if (it == all.end())
      throw InputError(fmt::format("--device {}: no {} device (see `misalloc devices`)", spec, spec));
  } else {
    size_t used = 0;
    long index = -1;
    try {
      index = std::stol(spec, &used);
    } catch (const std::exception&) {
    }
    if (used != spec.size() || index < 0 || index >= (long)all.size())
      throw InputError(fmt::format("--device '{}': expected auto, cpu, gpu or an index 0..{} (see `misalloc devices`)",
                                   spec, all.size() - 1));
    it = all.begin() + index;
  }
  Device dev{it->first, it->second, {}, {}};
  dev.context = cl::Context(dev.device);
  dev.queue = cl::CommandQueue(dev.context, dev.device, CL_QUEUE_PROFILING_ENABLE);
  return dev;
}

cl::Program buildProgram(const Device& device, const std::string& mainFile, const std::string& options) {
  cl::Program program(device.context, kernelSource(mainFile));
  try {
    program.build({device.device}, options.c_str());
  } catch (const cl::Error&) {
    throw DeviceError(fmt::format("building kernels/{} for {} failed with options '{}'. Build log:\n{}", mainFile,
                                  device.name(), options, program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device.device)));
  }
  return program;
}

double eventSeconds(const cl::Event& event) {
  return double(event.getProfilingInfo<CL_PROFILING_COMMAND_END>() - event.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
         1e-9;
}

}  // namespace misalloc
