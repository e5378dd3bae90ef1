#include "render/SamplerChoice.h"

namespace misalloc {

std::unique_ptr<StageSampler> makeStageSampler(const std::string& deviceSpec, std::unique_ptr<Device>& device,
                                               const Scene& scene, const SamplerConfig& config, int localSize) {
  if (deviceSpec == "host") return std::make_unique<HostSampler>(scene, config);
  if (!device) device = std::make_unique<Device>(openDevice(deviceSpec));
  return std::make_unique<Sampler>(*device, scene, config, localSize);
}

std::string samplerDeviceName(const std::unique_ptr<Device>& device) {
  return device ? device->name() : "host (C++ reference, OpenMP)";
}

}  // namespace misalloc
