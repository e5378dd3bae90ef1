#pragma once
#include <CLI/CLI.hpp>
#include <memory>
#include <string>

#include "cl/Device.h"
#include "render/Sampler.h"

namespace misalloc {

// The OpenCL work-group size unless --local-size says otherwise; reference has no
// --local-size.
constexpr int kDefaultLocalSize = 8;

// --device, as render, reference and compare take it, and the samplers it opens: the
// one place that reads the option.
class DeviceArgs {
 public:
  // Each command keeps the help wording it has always had.
  void add(CLI::App& command, const std::string& description);

  const std::string& spec() const { return spec_; }
  // The C++ sampler (HostSampler): the grid search's sums then take host memory.
  bool onHost() const { return spec_ == "host"; }

  // A sampler on the device asked for, opened at the first call and shared by the
  // samplers built later; they must not outlive this.
  std::unique_ptr<StageSampler> makeSampler(const Scene& scene, const SamplerConfig& config, int localSize);
  // The name a report gives the device.
  std::string name() const;

 private:
  std::string spec_ = "auto";
  std::unique_ptr<Device> device_;
};

}  // namespace misalloc
