#pragma once
#include <cstdint>
#include <vector>

#include "render/Method.h"
#include "render/Sampler.h"
#include "scene/ExrIO.h"

namespace misalloc {

struct Rendering {
  RgbImage image;
  std::vector<double> variance;  // per pixel: estimated variance of the luminance estimate
  double kernelSeconds = 0;      // device time of the sampling kernels (profiling events)
  double hostSeconds = 0;        // everything else: planning, transfers, reductions
  double wallSeconds = 0;
};

// Renders every pixel with `spp` samples split by `method`, in one stage.
Rendering render(StageSampler& sampler, const Scene& scene, Method method, Estimator estimator, int spp,
                 uint64_t seed);

// Estimated variance of a pixel's stage estimate from the per-technique moments of
// w = Y/p_α. Multi-sample: Σ_k n_k s_k² / N² (002 eq. 21 with estimated σ_k);
// one-sample: s² / N over all samples (002 Table 2).
double stageVariance(const StagePlan& plan, const StageResult& result, int pixel, Estimator estimator);

}  // namespace misalloc
