#include "cl/Device.h"

#include <fmt/format.h>

#include <algorithm>

#include "Error.h"
#include "cl/KernelSource.h"

namespace misalloc {
std::string mebibytes(uint64_t bytes) { return fmt::format("{:.0f} MiB", double(bytes) / (1 << 20)); }

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

Device withQueue(const cl::Platform& platform, const cl::Device& device) {
  Device dev{platform, device, {}, {}, {}, nullptr};
  dev.context = cl::Context(dev.device);
  dev.queue = cl::CommandQueue(dev.context, dev.device, CL_QUEUE_PROFILING_ENABLE);
  return dev;
}

// The most sub-devices of equal compute units that `d` can be split into; 0 if none.
cl_uint maxEqualSubDevices(const cl::Device& d) {
  std::vector<cl_device_partition_property> kinds = d.getInfo<CL_DEVICE_PARTITION_PROPERTIES>();
  if (std::find(kinds.begin(), kinds.end(), CL_DEVICE_PARTITION_EQUALLY) == kinds.end()) return 0;
  return std::min(d.getInfo<CL_DEVICE_PARTITION_MAX_SUB_DEVICES>(), d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>());
}

}  // namespace

std::string Device::name() const {
  return fmt::format("{} ({}){}", device.getInfo<CL_DEVICE_NAME>(), platform.getInfo<CL_PLATFORM_NAME>(),
                     part.empty() ? "" : ", " + part);
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
    const cl_uint subDevices = maxEqualSubDevices(d);
    const std::string type = hasType(d, CL_DEVICE_TYPE_GPU) ? "gpu" : "cpu";
    out << fmt::format("[{}] {} | {} | {} | {} compute units | {} MiB | {}{}\n", i, p.getInfo<CL_PLATFORM_NAME>(),
                       d.getInfo<CL_DEVICE_NAME>(), type, d.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>(),
                       d.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>() >> 20, d.getInfo<CL_DEVICE_VERSION>(),
                       subDevices > 1 ? fmt::format(" | sub-devices: --device {}{}:N, N = 2..{}",
                                                    type == "cpu" ? "cpu:N or --device " : "", i, subDevices)
                                      : "");
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
  return withQueue(it->first, it->second);
}

std::vector<Device> openAllDevices() {
  auto all = enumerateDevices();
  if (all.empty()) throw DeviceError(kInstallAdvice);
  std::vector<Device> devices;
  for (const auto& [platform, device] : all) devices.push_back(withQueue(platform, device));
  return devices;
}

std::vector<Device> openSubDevices(const std::string& spec, int count) {
  Device whole = openDevice(spec);
  const cl_uint most = maxEqualSubDevices(whole.device);
  if (count < 1 || cl_uint(count) > std::max<cl_uint>(most, 1) || (count > 1 && most < 2))
    throw InputError(fmt::format("--device {}:{}: {} splits into at most {} sub-devices of equal compute units", spec,
                                 count, whole.name(), std::max<cl_uint>(most, 1)));
  if (count == 1) return {std::move(whole)};
  const cl_uint units = whole.device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>() / cl_uint(count);
  const cl_device_partition_property equally[] = {CL_DEVICE_PARTITION_EQUALLY, cl_device_partition_property(units), 0};
  std::vector<cl::Device> parts;
  whole.device.createSubDevices(equally, &parts);
  parts.resize(size_t(count));
  // One context for the parts and the whole: buffers made in it serve every part
  // (sampling/Sampler.h, SceneBuffers), and the whole device can run what is not split
  // into tiles over them (the grid search) on all its compute units.
  std::vector<cl::Device> members = parts;
  members.push_back(whole.device);
  const cl::Context shared(members);
  auto wholeInShared =
      std::make_shared<Device>(Device{whole.platform, whole.device, shared,
                                      cl::CommandQueue(shared, whole.device, CL_QUEUE_PROFILING_ENABLE), "", nullptr});
  std::vector<Device> devices;
  for (int i = 0; i < count; ++i) {
    Device part{whole.platform,
                parts[size_t(i)],
                shared,
                cl::CommandQueue(shared, parts[size_t(i)], CL_QUEUE_PROFILING_ENABLE),
                fmt::format("sub-device {}/{}", i + 1, count),
                wholeInShared};
    devices.push_back(std::move(part));
  }
  return devices;
}

cl::Program buildProgram(const Device& device, const std::string& mainFile, const std::string& options) {
  const std::string key = mainFile + " " + options;
  if (auto built = device.programs->find(key); built != device.programs->end()) return built->second;
  cl::Program program(device.context, kernelSource(mainFile));
  try {
    program.build({device.device}, options.c_str());
  } catch (const cl::Error&) {
    throw DeviceError(fmt::format("building kernels/{} for {} failed with options '{}'. Build log:\n{}", mainFile,
                                  device.name(), options, program.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device.device)));
  }
  device.programs->emplace(key, program);
  return program;
}

double eventSeconds(const cl::Event& event) {
  return double(event.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                event.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
         1e-9;
}

DeviceError explainBufferError(const cl::Error& e, const Device& device, const std::string& cause, int pixels) {
  const std::string code = fmt::format("OpenCL error {} in {}", e.err(), e.what());
  switch (e.err()) {
    case CL_INVALID_BUFFER_SIZE:
    case CL_MEM_OBJECT_ALLOCATION_FAILURE:
    case CL_OUT_OF_RESOURCES:
      return DeviceError(
          fmt::format("{} for {} pixels: a buffer is larger than {} can hold: at most {} in one buffer, {} in all ({})",
                      cause, pixels, device.name(), mebibytes(device.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>()),
                      mebibytes(device.device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>()), code));
    default:
      return DeviceError(code);
  }
}

}  // namespace misalloc
