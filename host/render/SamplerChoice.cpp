#include "render/SamplerChoice.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>

#include "Error.h"

namespace misalloc {
namespace {

std::string mebibytes(uint64_t bytes) { return fmt::format("{:.0f} MiB", double(bytes) / (1 << 20)); }

// The option that sized the sampler's largest buffers: the grid search's sums, the
// stored samples, or else the image.
std::string bufferOption(const Scene& scene, const SamplerConfig& config) {
  if (config.gridSize > 0) return fmt::format("--grid-u {}", config.gridSize);
  if (config.sampleCapacity > 0) return fmt::format("--spp (it stores {} samples per pixel)", config.sampleCapacity);
  return fmt::format("--size {}x{}", scene.grid.width, scene.grid.height);
}

// An OpenCL error that an option caused, said in words with the option and the
// device's limit; any other error unchanged.
DeviceError explain(const cl::Error& e, const Device& device, const Scene& scene, const SamplerConfig& config,
                    int localSize) {
  const std::string code = fmt::format("OpenCL error {} in {}", e.err(), e.what());
  switch (e.err()) {
    case CL_INVALID_WORK_GROUP_SIZE:
      return DeviceError(fmt::format("--local-size {}: {} runs at most {} work-items per work-group ({})", localSize,
                                     device.name(), device.device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>(), code));
    case CL_INVALID_BUFFER_SIZE:
    case CL_MEM_OBJECT_ALLOCATION_FAILURE:
    case CL_OUT_OF_RESOURCES:
      return DeviceError(fmt::format(
          "{} for {} pixels: a buffer is larger than {} can hold: at most {} in one buffer, {} in all ({})",
          bufferOption(scene, config), scene.pixelCount(), device.name(),
          mebibytes(device.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>()),
          mebibytes(device.device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>()), code));
    default:
      return DeviceError(code);
  }
}

// The envmap's sampling tables must fit the device, each in one buffer: refused
// before they are uploaded, with the figures.
void requireTablesFit(const Device& device, const Scene& scene) {
  const EnvmapTables& t = scene.tables;
  const uint64_t sizes[] = {t.texels.size() * sizeof(float), t.cdfTable.size() * sizeof(float),
                            t.aliasTable.size() * sizeof(uint32_t)};
  const uint64_t largest = *std::max_element(std::begin(sizes), std::end(sizes));
  const uint64_t total = sizes[0] + sizes[1] + sizes[2];
  const uint64_t maxAlloc = device.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  const uint64_t global = device.device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  if (largest > maxAlloc || total > global)
    throw InputError(fmt::format(
        "--envmap {}: its {}×{} texels need {} of sampling tables ({:.0f} B per texel, {} in one buffer); {} holds "
        "at most {} in one buffer and {} in all",
        scene.options.envmap, t.width, t.height, mebibytes(total), double(total) / (double(t.width) * t.height),
        mebibytes(largest), device.name(), mebibytes(maxAlloc), mebibytes(global)));
}

}  // namespace

std::unique_ptr<StageSampler> makeStageSampler(const std::string& deviceSpec, std::unique_ptr<Device>& device,
                                               const Scene& scene, const SamplerConfig& config, int localSize) {
  if (deviceSpec == "host") return std::make_unique<HostSampler>(scene, config);
  if (!device) device = std::make_unique<Device>(openDevice(deviceSpec));
  requireTablesFit(*device, scene);
  try {
    // The constructor allocates every buffer and launches the kernel once.
    return std::make_unique<Sampler>(*device, scene, config, localSize);
  } catch (const cl::Error& e) {
    throw explain(e, *device, scene, config, localSize);
  }
}

std::string samplerDeviceName(const std::unique_ptr<Device>& device) {
  return device ? device->name() : "host (C++ reference, OpenMP)";
}

}  // namespace misalloc
