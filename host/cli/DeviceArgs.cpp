#include "cli/DeviceArgs.h"

#include "render/SamplerChoice.h"

namespace misalloc {

void DeviceArgs::add(CLI::App& command, const std::string& description) {
  command.add_option("--device", spec_, description)->capture_default_str();
}

std::unique_ptr<StageSampler> DeviceArgs::makeSampler(const Scene& scene, const SamplerConfig& config, int localSize) {
  return makeStageSampler(spec_, device_, scene, config, localSize);
}

std::string DeviceArgs::name() const { return samplerDeviceName(device_); }

}  // namespace misalloc
