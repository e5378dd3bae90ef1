#pragma once
#include <CL/opencl.hpp>
#include <cstdint>
#include <string>

#include "cl/Device.h"
#include "render/Scene.h"
#include "render/Stage.h"

namespace misalloc {

// The `-D` options that compile kernels/sample.cl for exactly this scene and
// estimator: number of techniques, envmap sampler, analytic envmap, estimator and
// the work-group size.
std::string sampleKernelOptions(const Scene& scene, Estimator estimator, int localSize);

// Takes one sampling stage for every pixel.
class StageSampler {
 public:
  virtual ~StageSampler() = default;
  virtual StageResult run(const StagePlan& plan, uint64_t seed) = 0;
};

// Runs kernels/sample.cl (sampleStage) on a device. The program is built and the
// scene uploaded once; each run() takes one stage for every pixel.
class Sampler : public StageSampler {
 public:
  Sampler(const Device& device, const Scene& scene, Estimator estimator, int localSize = 8);
  StageResult run(const StagePlan& plan, uint64_t seed) override;

 private:
  const Device& device_;
  const Scene& scene_;
  int localSize_;
  bool doubleSums_;
  cl::Kernel kernel_;
  cl::Buffer texels_, samplerTable_, aliasIndex_, brdfParams_;
};

// The C++ reference of Sampler: the same kernels/pixel.h functions, one pixel per
// OpenMP iteration.
class HostSampler : public StageSampler {
 public:
  HostSampler(const Scene& scene, Estimator estimator) : scene_(scene), estimator_(estimator) {}
  StageResult run(const StagePlan& plan, uint64_t seed) override;

 private:
  const Scene& scene_;
  Estimator estimator_;
};

}  // namespace misalloc
