#pragma once
#include <CL/opencl.hpp>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cl/Device.h"
#include "sampling/StageSampler.h"

namespace misalloc {

// The `-D` options that compile kernels/sample.cl for exactly this scene, estimator,
// statistics and work-group size; `pixelLanes` > 0 adds samplePixelStage at that many
// lanes, with 64-bit table reads split in two (docs/pocl.md, rule 10).
std::string sampleKernelOptions(const Scene& scene, const SamplerConfig& config, int localSize, int pixelLanes = 0,
                                int groupPixels = 0);

// The lanes of samplePixelStage for this scene and config on a device whose
// DeviceLimits::pixelLanes is `deviceLanes` (0: not a CPU), or 0 where the stages keep
// sampleStage. Measured on haswell (docs/results.md, "One pixel per work-group on a
// CPU"): the CDF sampler's searches and resampling's candidates ran slower one pixel per
// work-group.
int samplePixelLanes(const Scene& scene, const SamplerConfig& config, int deviceLanes);

// A pixel's rows of local memory in the sampling kernels built for `config`
// (kernels/pixel_layout.h): with the pilot's cells where it keeps statistics
// (stageTables).
int samplePixelRows(const Scene& scene, const SamplerConfig& config);

// The pixels a work-group of samplePixelStage at `lanes` lanes takes: `lanes`, or the
// largest smaller power of two whose rows fit `localMemBytes` (pixelStageLocalBytes) in
// the kernels with and without the config's statistics: a per-pixel table of many
// cells. 0 where not even one pixel's fit.
int pixelStageGroupPixels(const Scene& scene, const SamplerConfig& config, int lanes, uint64_t localMemBytes);

// A scene's read-only device buffers: the envmap's tables and the BRDF grid. Devices
// that share a context (the sub-devices of one device, cl/Device.h) share one copy, so
// that their caches hold one set of tables.
class SceneBuffers {
 public:
  // `withPilot`: the pilot's tables too (Scene::pilotTables), for samplers that keep
  // statistics; others leave them out, as large as the scene's own.
  SceneBuffers(const Device& device, const Scene& scene, bool withPilot);
  cl_context context() const { return context_; }

  // An EnvmapTables' buffers (kernels/envmap.h, EnvmapView).
  struct Envmap {
    cl::Buffer texels, cdfTable, aliasTable, blockProbs;
  };
  // The tables of a stage (stageTables): the pilot's are the same buffers where the
  // scene has none of its own. Throws std::logic_error for the pilot's left out.
  const Envmap& envmap(bool keepsStatistics) const;

  cl::Buffer productFloats, productWords, shadingPoints;

 private:
  cl_context context_;
  Envmap envmap_, pilotEnvmap_;
};

// Runs kernels/sample.cl on a device: sampleStage, across pixels; on a CPU, stages
// without running sums (with or without stored samples) run samplePixelStage, a
// work-group of its native float width L taking L pixels, one after another, each
// across its lanes. The program is built and the scene uploaded once; each run() takes
// one stage for every pixel.
class Sampler : public StageSampler {
 public:
  // localSize 0: the device's own (cl/LaunchShape.h); > 0: --local-size, checked against it.
  // `device` and `scene` must outlive the sampler (ARCHITECTURE.md, Lifetimes).
  // `sceneBuffers`: made for this device's context, shared with other samplers, with the
  // pilot's tables where `config` keeps statistics; null: its own.
  Sampler(const Device& device, const Scene& scene, const SamplerConfig& config = {}, int localSize = 0,
          std::shared_ptr<const SceneBuffers> sceneBuffers = nullptr);
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override;

  std::vector<double> statistics() override;
  std::vector<float> storedSamples() override;
  void loadStatistics(const std::vector<double>& stats) override;
  void loadStoredSamples(const std::vector<float>& samples) override;
  // A sub-device's whole device, which shares its context and so reads the stored
  // samples where they are: a search is not split into tiles.
  const Device* storedSampleDevice() const override { return device_.whole ? device_.whole.get() : &device_; }
  StoredSampleBuffer storedSampleBuffer() override { return {storedSampleDevice(), &samples_, nullptr}; }

  std::vector<DeviceShare> deviceShares() const override;
  std::string launchIdentity() const override { return launchIdentity_; }
  int launchGroupSize() const override { return localSize_; }
  int pixelLanes(bool keepsStatistics) const override { return keepsStatistics ? statisticsLanes_ : pixelLanes_; }

 protected:
  void forgetStages() override;

 private:
  // Whether `plan`'s stage runs the kernel that keeps the config's statistics.
  bool storesStatistics(const StagePlan& plan) const { return plan.keepStatistics && keepsStatistics(config_); }
  // runPixels over the pixels of `order` (sampledPixels or coherentPixelOrder); the
  // other pixels of `range` take no samples.
  StageResult runOrder(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range,
                       const std::vector<int32_t>& order);
  // The plan's optimal-weight coefficients of `range` (zeros where it has none) into
  // coefficients_.
  void writeCoefficients(const StagePlan& plan, PixelRange range);

  const Device& device_;
  int localSize_;
  int pixelLanes_;       // > 0: plainKernel_ is samplePixelStage
  int statisticsLanes_;  // > 0: kernel_ is samplePixelStage too (stored samples, no running sums)
  int groupPixels_;      // samplePixelStage's pixels a work-group
  bool doubleSums_;
  cl::Kernel kernel_, plainKernel_;  // with the config's statistics, and without (plainConfig)
  std::shared_ptr<const SceneBuffers> sceneBuffers_;
  cl::Buffer stats_, samples_;
  // A stage's per-pixel inputs and outputs, whole-image sized so that a tile writes its rows.
  cl::Buffer counts_, firstIndex_, pixelOrder_, rgb_, moments_;
  cl::Buffer coefficients_;  // --weights optimal: a_{c,k} per pixel (StagePlan::optimalCoefficients)
  DeviceShare share_;        // since reset()
  std::string launchIdentity_;
};

}  // namespace misalloc
