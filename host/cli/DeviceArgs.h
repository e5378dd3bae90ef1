#pragma once
#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "sampling/SamplerChoice.h"

namespace misalloc {

// --local-size when not given: each device's own (cl/LaunchShape.h); reference has no
// --local-size.
constexpr int kDefaultLocalSize = 0;
inline constexpr const char* kLocalSizeHelp =
    "OpenCL work-group size of the sampling kernel (default: per device, 8 on a CPU, up to 256 on a GPU)";

// --device LIST, as render, reference and compare take it, and the samplers it opens:
// the one place that reads the option.
class DeviceArgs {
 public:
  // Each command keeps the help wording it has always had.
  void add(CLI::App& command, const std::string& description);

  const std::string& spec() const { return spec_; }
  // The list names the C++ sampler (HostSampler): the grid search's sums then take host memory.
  bool onHost() const { return SamplerDevices(spec_).includesHost(); }
  int samplerCount() const { return SamplerDevices(spec_).samplerCount(); }

  // A sampler on the devices asked for, opened at the first call and shared by the
  // samplers built later; they must not outlive this.
  std::unique_ptr<StageSampler> makeSampler(const Scene& scene, const SamplerConfig& config, int localSize);
  // The name a report gives the devices.
  std::string name() const;
  // The devices, opened at the first sampler; a caller that renders again with the same
  // --device (the Python module's scene) hands them to the next DeviceArgs with `reuse`,
  // sharing their contexts and built programs.
  std::shared_ptr<SamplerDevices> devices();
  void reuse(std::shared_ptr<SamplerDevices> devices);

 private:
  std::string spec_ = "auto";
  std::shared_ptr<SamplerDevices> devices_;
};

}  // namespace misalloc
