#pragma once
#include <string>
#include <vector>

namespace misalloc {

// One device's part in the stages since a sampler's reset(), for the report.
struct DeviceShare {
  std::string name;
  std::string launch;         // its local size and why (cl/LaunchShape.h); empty on the host
  long long pixelStages = 0;  // pixels it ran, summed over the stages
  long long samples = 0;      // samples it took
  int tiles = 0;              // kernel launches
  double kernelSeconds = 0;   // its own device time
  std::string failure;        // why it stopped, if it failed: its tiles ran elsewhere

  // The same device with nothing run yet (StageSampler::reset).
  DeviceShare restarted() const {
    DeviceShare fresh;
    fresh.name = name;
    fresh.launch = launch;
    return fresh;
  }
};

// Where a sampler's stages since its reset() ran, for the report.
class DeviceReport {
 public:
  virtual ~DeviceReport() = default;

  // Every device's share (one entry for a single device), and how far apart their
  // last tiles finished.
  virtual std::vector<DeviceShare> deviceShares() const = 0;
  virtual double imbalanceSeconds() const { return 0; }
};

}  // namespace misalloc
