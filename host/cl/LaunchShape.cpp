#include "cl/LaunchShape.h"

#include <CL/cl_ext.h>
#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <vector>

#include "Error.h"
#include "KernelCode.h"

namespace misalloc {
namespace {

// PoCL vectorises a work-group across 8 work-items fastest (docs/pocl.md, rule 4).
constexpr int kCpuLocalSize = 8;
constexpr int kGpuLocalSizes[] = {256, 128, 64, 32};

std::optional<cl_uint> vendorLockstepWidth(const cl::Device& device) {
  const std::string extensions = device.getInfo<CL_DEVICE_EXTENSIONS>();
  cl_uint width = 0;
  if (extensions.find("cl_nv_device_attribute_query") != std::string::npos &&
      clGetDeviceInfo(device(), CL_DEVICE_WARP_SIZE_NV, sizeof(width), &width, nullptr) == CL_SUCCESS && width > 0)
    return width;
  if (extensions.find("cl_amd_device_attribute_query") != std::string::npos &&
      clGetDeviceInfo(device(), CL_DEVICE_WAVEFRONT_WIDTH_AMD, sizeof(width), &width, nullptr) == CL_SUCCESS &&
      width > 0)
    return width;
  return std::nullopt;
}

std::string kib(uint64_t bytes) {
  return bytes % 1024 == 0 ? fmt::format("{} KiB", bytes / 1024) : fmt::format("{:.1f} KiB", bytes / 1024.0);
}

// Why `size` does not fit the device, or nothing if it does.
std::optional<std::string> misfit(const DeviceLimits& limits, size_t bytes, int size) {
  if (size_t(size) > limits.maxWorkGroupSize)
    return fmt::format("{} exceeds the device's {} work-items per group", size, limits.maxWorkGroupSize);
  if (bytes > limits.localMemBytes)
    return fmt::format("{} would need {} of local memory, the device has {}", size, kib(bytes),
                       kib(limits.localMemBytes));
  return std::nullopt;
}

}  // namespace

DeviceLimits deviceLimits(const cl::Device& device) {
  DeviceLimits limits;
  const cl_device_type type = device.getInfo<CL_DEVICE_TYPE>();
  limits.cpu = (type & CL_DEVICE_TYPE_CPU) != 0;
  limits.maxWorkGroupSize = device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>();
  limits.localMemBytes = device.getInfo<CL_DEVICE_LOCAL_MEM_SIZE>();
  if ((type & CL_DEVICE_TYPE_GPU) != 0) limits.preferredMultiple = vendorLockstepWidth(device).value_or(32);
  if (limits.cpu) {
    const int width =
        int(std::min<size_t>(device.getInfo<CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT>(), limits.maxWorkGroupSize));
    limits.pixelLanes = 1;
    while (limits.pixelLanes * 2 <= std::min(width, kMaxPixelLanes)) limits.pixelLanes *= 2;
  }
  return limits;
}

size_t sampleKernelLocalBytes(int localSize, int statSlots, bool doubleSums, int pixelRows) {
  const size_t acc = doubleSums ? sizeof(double) : sizeof(float);
  return size_t(localSize) * ((kern::SUM_COUNT + size_t(statSlots)) * acc + (size_t(pixelRows) + 1) * sizeof(cl_int));
}

size_t pixelStageLocalBytes(int lanes, int pixels, int pixelRows) {
  // Bounds for the sampled pixel's copy (fewer rows than the pixel's, two words apart)
  // and PixelSums (at most 16 sums of 8 bytes).
  constexpr size_t sumsBytes = 16 * sizeof(double);
  return size_t(pixels) * size_t(kern::pixelRowBlock(pixelRows)) * sizeof(cl_int) +
         (size_t(pixelRows) + 1) * 2 * sizeof(cl_int) +
         size_t(kern::TERM_COUNT) * MA_PASSES_PER_CHUNK * size_t(lanes) * sizeof(float) + sumsBytes;
}

LaunchShape chooseLocalSize(const DeviceLimits& limits, const std::function<size_t(int)>& localBytes,
                            int overrideLocalSize) {
  const std::string kind = limits.cpu ? "CPU" : "GPU";
  if (overrideLocalSize < 0) throw InputError("--local-size must be at least 1");
  if (overrideLocalSize > 0) {
    const size_t bytes = localBytes(overrideLocalSize);
    if (auto why = misfit(limits, bytes, overrideLocalSize))
      throw DeviceError(
          fmt::format("--local-size {}: the sampling kernel does not fit this {}: {}", overrideLocalSize, kind, *why));
    return {overrideLocalSize, fmt::format("{}: {} work-items as --local-size asked, {} of {} local memory", kind,
                                           overrideLocalSize, kib(bytes), kib(limits.localMemBytes))};
  }
  std::vector<int> candidates;
  if (limits.cpu) {
    candidates.push_back(kCpuLocalSize);
  } else {
    for (int size : kGpuLocalSizes)
      if (size_t(size) % std::max<size_t>(limits.preferredMultiple, 1) == 0) candidates.push_back(size);
  }
  // Below the preferred sizes lanes go idle, but the kernel still runs.
  const int below = candidates.empty() ? kGpuLocalSizes[0] : candidates.back() / 2;
  for (int size = below; size >= 1; size /= 2) candidates.push_back(size);

  std::optional<std::string> refused;  // why the next larger size did not fit
  for (int size : candidates) {
    const size_t bytes = localBytes(size);
    if (auto why = misfit(limits, bytes, size)) {
      refused = why;
      continue;
    }
    std::string line =
        fmt::format("{}: {} work-items, {} of {} local memory", kind, size, kib(bytes), kib(limits.localMemBytes));
    if (limits.cpu && size == kCpuLocalSize) line += " (PoCL vectorises 8 best, docs/pocl.md rule 4)";
    if (refused) line += "; " + *refused;
    return {size, line};
  }
  throw DeviceError(fmt::format("the sampling kernel does not fit this {} even at one work-item: {}", kind, *refused));
}

}  // namespace misalloc
