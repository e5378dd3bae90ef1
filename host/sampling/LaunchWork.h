#pragma once
// How the sampling kernel walks a stage's pixels, and the work a launch does: what the
// cost model (CostModel.h) predicts a launch's time from.
#include <cstdint>
#include <vector>

#include "sampling/Stage.h"

namespace misalloc {

// The pixels of `range` that take samples this stage, in index order: samplePixelStage's
// (kernels/sample.cl), whose lanes sample one pixel at a time, so that like counts gain
// nothing, and the pixels of a pair or quad that sample one table (kernels/pixel_pairs.h)
// lie side by side, where one lane builds it for all.
std::vector<int32_t> sampledPixels(const StagePlan& plan, PixelRange range);

// The order in which sampleStage's work-items take the pixels of `range`. A work-group runs each
// technique's loop for its largest count (kernels/sample.cl, sampleStage), so pixels
// with like counts share work-groups: sorted by (n_0, …, n_{M−2}) with a stable sort,
// ties by index; n_{M−1} = N − the rest. Each pixel's arithmetic does not depend on its
// work-group, so the order changes the time only, never the result. Pixels that take
// no samples this stage (the background) are left out: a launch of them would write
// zero sums and cost a work-group each, and the caller writes those zeros itself.
std::vector<int32_t> coherentPixelOrder(const StagePlan& plan, PixelRange range);

// Whether pixel `p` takes samples in this stage.
inline bool takesSamples(const StagePlan& plan, int p) {
  const int32_t* counts = plan.counts.data() + size_t(p) * size_t(plan.techniqueCount);
  for (int k = 0; k < plan.techniqueCount; ++k)
    if (counts[k] > 0) return true;
  return false;
}

// What one launch executes: per technique, the sample slots Σ over work-groups of
// (group size) · (the group's largest n_k), padding work-items included: a work-item
// whose own n_k is smaller runs the loop too, its surplus samples not counted, and a
// group whose n_k are all 0 runs it once where k lies between the first technique and
// the last. The one-sample estimator runs one pass of N samples, each of the technique
// it draws; its slots are the counts' expectation.
struct LaunchWork {
  bool keepsStatistics = false;  // the kernel with running sums and stored samples
  std::vector<double> slots;     // [k]
};

// `groupSize` 1: a sampler that runs each pixel's counts alone (HostSampler).
// `pixelLanes` > 0: pixels sampled one at a time by a work-group of that many lanes
// (samplePixelStage), which runs each technique's n_k rounded up to a multiple of the
// lanes, and one pass of them for n_k = 0 between the first technique and the last;
// the one-sample estimator, N rounded up, shared by the counts' expectation.
LaunchWork launchWork(const StagePlan& plan, Estimator estimator, int groupSize, int pixelLanes = 0);

}  // namespace misalloc
