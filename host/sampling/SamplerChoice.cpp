#include "sampling/SamplerChoice.h"

#include <fmt/format.h>

#include <algorithm>
#include <iterator>
#include <map>
#include <vector>

#include "Error.h"
#include "sampling/HostSampler.h"
#include "sampling/TiledSampler.h"

namespace misalloc {
namespace {

// The option that sized the sampler's largest buffers: the stored samples, or else
// the image.
std::string bufferOption(const Scene& scene, const SamplerConfig& config) {
  if (config.sampleCapacity > 0) return fmt::format("--spp (it stores {} samples per pixel)", config.sampleCapacity);
  return fmt::format("--size {}x{}", scene.grid.width, scene.grid.height);
}

// An OpenCL error that an option caused, said in words with the option and the
// device's limit; any other error unchanged.
DeviceError explain(const cl::Error& e, const Device& device, const Scene& scene, const SamplerConfig& config,
                    int localSize) {
  if (e.err() == CL_INVALID_WORK_GROUP_SIZE)
    return DeviceError(
        fmt::format("--local-size {}: {} runs at most {} work-items per work-group (OpenCL error {} in {})", localSize,
                    device.name(), device.device.getInfo<CL_DEVICE_MAX_WORK_GROUP_SIZE>(), e.err(), e.what()));
  return explainBufferError(e, device, bufferOption(scene, config), scene.pixelCount());
}

// The envmap's sampling tables, and the pilot's where the config keeps statistics
// (SceneBuffers), must fit the device, each in one buffer: refused before they are
// uploaded, with the figures.
void requireTablesFit(const Device& device, const Scene& scene, const SamplerConfig& config) {
  const EnvmapTables& t = scene.tables;
  const EnvmapTables& pilot = stageTables(scene, keepsStatistics(config));
  std::vector<const EnvmapTables*> uploaded{&t};
  if (&pilot != &t) uploaded.push_back(&pilot);
  uint64_t largest = 0, total = 0;
  for (const EnvmapTables* tables : uploaded) {
    const uint64_t sizes[] = {tables->texels.size() * sizeof(float), tables->cdfTable.size() * sizeof(float),
                              tables->aliasTable.size() * sizeof(uint32_t), tables->blockProbs.size() * sizeof(float)};
    largest = std::max(largest, *std::max_element(std::begin(sizes), std::end(sizes)));
    total += sizes[0] + sizes[1] + sizes[2] + sizes[3];
  }
  const uint64_t maxAlloc = device.device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
  const uint64_t global = device.device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
  if (largest > maxAlloc || total > global)
    throw InputError(fmt::format(
        "--envmap {}: its {}×{} texels need {} of sampling tables ({:.0f} B per texel, {} in one buffer); {} holds "
        "at most {} in one buffer and {} in all",
        scene.options.envmap, t.width, t.height, mebibytes(total), double(total) / (double(t.width) * t.height),
        mebibytes(largest), device.name(), mebibytes(maxAlloc), mebibytes(global)));
}

// The entries of `--device LIST`; throws InputError for an empty entry.
std::vector<std::string> deviceEntries(const std::string& list) {
  std::vector<std::string> entries;
  size_t begin = 0;
  while (true) {
    size_t comma = list.find(',', begin);
    std::string entry = list.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    if (entry.empty()) throw InputError(fmt::format("--device '{}': an empty entry", list));
    entries.push_back(entry);
    if (comma == std::string::npos) return entries;
    begin = comma + 1;
  }
}

// "D:N" → (D, N); N must be a whole number of at least 1.
std::pair<std::string, int> subDeviceEntry(const std::string& entry) {
  const size_t colon = entry.rfind(':');
  const std::string countText = entry.substr(colon + 1);
  size_t used = 0;
  int count = 0;
  try {
    count = std::stoi(countText, &used);
  } catch (const std::exception&) {
  }
  if (used != countText.size() || count < 1 || colon == 0)
    throw InputError(fmt::format("--device {}: expected DEVICE:N, a device and N ≥ 1 sub-devices", entry));
  return {entry.substr(0, colon), count};
}

// `shared`: the scene buffers made so far, one per context, for devices that share one.
std::unique_ptr<StageSampler> makeDeviceSampler(const Device* device, const Scene& scene, const SamplerConfig& config,
                                                int localSize,
                                                std::map<cl_context, std::shared_ptr<const SceneBuffers>>& shared) {
  if (!device) return std::make_unique<HostSampler>(scene, config);
  requireTablesFit(*device, scene, config);
  try {
    std::shared_ptr<const SceneBuffers>& buffers = shared[device->context()];
    if (!buffers) buffers = std::make_shared<SceneBuffers>(*device, scene, keepsStatistics(config));
    // The constructor allocates every other buffer and launches the kernel once.
    return std::make_unique<Sampler>(*device, scene, config, localSize, buffers);
  } catch (const cl::Error& e) {
    throw explain(e, *device, scene, config, localSize);
  }
}

}  // namespace

SamplerDevices::SamplerDevices(std::string list) : list_(std::move(list)) {}

void SamplerDevices::open() {
  if (opened_) return;
  std::vector<std::unique_ptr<Device>> devices;
  for (const std::string& entry : deviceEntries(list_)) {
    std::vector<Device> opened;
    if (entry == "host")
      devices.push_back(nullptr);
    else if (entry == "all")
      opened = openAllDevices();
    else if (entry.find(':') != std::string::npos) {
      auto [spec, count] = subDeviceEntry(entry);
      opened = openSubDevices(spec, count);
    } else
      opened.push_back(openDevice(entry));
    for (Device& d : opened) devices.push_back(std::make_unique<Device>(std::move(d)));
  }
  devices_ = std::move(devices);
  opened_ = true;
}

std::unique_ptr<StageSampler> SamplerDevices::makeSampler(const Scene& scene, const SamplerConfig& config,
                                                          int localSize) {
  open();
  std::map<cl_context, std::shared_ptr<const SceneBuffers>> shared;
  if (devices_.size() == 1) return makeDeviceSampler(devices_[0].get(), scene, config, localSize, shared);
  std::vector<std::unique_ptr<StageSampler>> members;
  for (const auto& device : devices_)
    members.push_back(makeDeviceSampler(device.get(), scene, config, localSize, shared));
  return std::make_unique<TiledSampler>(scene, config, std::move(members));
}

std::string SamplerDevices::name() const {
  std::string joined;
  for (const auto& device : devices_)
    joined += (joined.empty() ? "" : " + ") + (device ? device->name() : std::string(kHostSamplerName));
  return joined.empty() ? list_ : joined;
}

int SamplerDevices::samplerCount() const {
  int count = 0;
  for (const std::string& entry : deviceEntries(list_)) {
    if (entry == "all")
      count += int(enumerateDevices().size());
    else if (entry != "host" && entry.find(':') != std::string::npos)
      count += subDeviceEntry(entry).second;
    else
      ++count;
  }
  return count;
}

bool SamplerDevices::includesHost() const {
  for (const std::string& entry : deviceEntries(list_))
    if (entry == "host") return true;
  return false;
}

}  // namespace misalloc
