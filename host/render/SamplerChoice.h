#pragma once
#include <memory>
#include <string>

#include "cl/Device.h"
#include "render/Sampler.h"

namespace misalloc {

// The sampler that `--device` asks for: "host" is the C++ reference (HostSampler),
// anything else an OpenCL device (openDevice), opened at the first call and kept in
// `device` so that samplers built later share it.
std::unique_ptr<StageSampler> makeStageSampler(const std::string& deviceSpec, std::unique_ptr<Device>& device,
                                               const Scene& scene, const SamplerConfig& config, int localSize);

// The name a report gives the sampler's device.
std::string samplerDeviceName(const std::unique_ptr<Device>& device);

}  // namespace misalloc
