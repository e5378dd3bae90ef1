#pragma once
// The OpenMP peer that a good C++ programmer would write for kernels/sample.cl's plain
// multi-sample stage: the kernel's own functions (host/KernelCode.h), each technique's
// samples in a loop of their own as the kernel runs them, that loop `omp simd` so that
// g++ vectorises it across samples as PoCL vectorises the kernel across pixels.
// HostSampler, the kernel's reference, picks the technique per sample and stays scalar.
#include <cstdint>

#include "sampling/Stage.h"
#include "scene/Scene.h"

namespace misalloc::bench {

class VectorisedPeer {
 public:
  // Throws std::invalid_argument for a scene it does not run: it is specialised, as the
  // kernel is compiled, for the benchmark's shape (two techniques, the plain pdf, a
  // map's texels for radiance).
  explicit VectorisedPeer(const Scene& scene);

  // The stage's estimate and moments of every pixel, as StageSampler::run gives them
  // for the balance heuristic without statistics; the samples drawn are the kernel's.
  StageResult run(const StagePlan& plan, uint64_t seed) const;

 private:
  const Scene& scene_;
};

}  // namespace misalloc::bench
