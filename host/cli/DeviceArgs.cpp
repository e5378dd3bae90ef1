#include "cli/DeviceArgs.h"

namespace misalloc {

void DeviceArgs::add(CLI::App& command, const std::string& description) {
  command.add_option("--device", spec_, description)->capture_default_str();
}

std::unique_ptr<StageSampler> DeviceArgs::makeSampler(const Scene& scene, const SamplerConfig& config, int localSize) {
  return devices()->makeSampler(scene, config, localSize);
}

std::shared_ptr<SamplerDevices> DeviceArgs::devices() {
  if (!devices_) devices_ = std::make_shared<SamplerDevices>(spec_);
  return devices_;
}

void DeviceArgs::reuse(std::shared_ptr<SamplerDevices> devices) { devices_ = std::move(devices); }

std::string DeviceArgs::name() const { return devices_ ? devices_->name() : spec_; }

}  // namespace misalloc
