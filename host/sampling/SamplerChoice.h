#pragma once
#include <memory>
#include <string>
#include <vector>

#include "cl/Device.h"
#include "sampling/Sampler.h"

namespace misalloc {

// The devices `--device LIST` names: comma-separated entries, each auto, cpu, gpu, an
// index of `misalloc devices`, host (the C++ reference, HostSampler), all (every OpenCL
// device) or D:N (device D split into N sub-devices, openSubDevices). Opened at the
// first sampler and kept, so that samplers built later share them.
class SamplerDevices {
 public:
  explicit SamplerDevices(std::string list);

  // One device: its sampler; several: a TiledSampler over one sampler each.
  std::unique_ptr<StageSampler> makeSampler(const Scene& scene, const SamplerConfig& config, int localSize);
  // What a report names: the devices, joined by " + ".
  std::string name() const;
  bool includesHost() const;
  // How many samplers the list makes, from the list alone (`all` asks the platforms):
  // each holds its own running sums and stored samples.
  int samplerCount() const;

 private:
  void open();

  std::string list_;
  bool opened_ = false;
  std::vector<std::unique_ptr<Device>> devices_;  // nullptr: the host
};

}  // namespace misalloc
