#include "sampling/LaunchWork.h"

#include <algorithm>

#include "KernelCode.h"

namespace misalloc {

std::vector<int32_t> sampledPixels(const StagePlan& plan, PixelRange range) {
  std::vector<int32_t> order;
  order.reserve(size_t(range.size()));
  for (int p = range.begin; p < range.end; ++p)
    if (takesSamples(plan, p)) order.push_back(p);
  return order;
}

std::vector<int32_t> coherentPixelOrder(const StagePlan& plan, PixelRange range) {
  std::vector<int32_t> order = sampledPixels(plan, range);
  const size_t M = size_t(plan.techniqueCount);
  auto before = [&](int32_t a, int32_t b) {
    const int* countsA = plan.counts.data() + size_t(a) * M;
    const int* countsB = plan.counts.data() + size_t(b) * M;
    return std::lexicographical_compare(countsA, countsA + M - 1, countsB, countsB + M - 1);
  };
  // A comparison sort: its memory scales with the pixels, where a counting sort's
  // buckets 0..N took 4 bytes per sample of the stage. Fixed splits and the pilot are
  // in order already, and a check is cheaper than the sort.
  if (!std::is_sorted(order.begin(), order.end(), before)) std::stable_sort(order.begin(), order.end(), before);
  return order;
}

LaunchWork launchWork(const StagePlan& plan, Estimator estimator, int groupSize, int pixelLanes) {
  const int M = plan.techniqueCount;
  const int pixels = int(plan.counts.size() / size_t(M));
  LaunchWork work{plan.keepStatistics, std::vector<double>(M, 0.0)};
  if (pixelLanes > 0) {
    auto passSlots = [&](int n, int leastPasses) {
      return double(std::max(leastPasses, (n + pixelLanes - 1) / pixelLanes) * pixelLanes);
    };
    const bool oneSample = estimator == Estimator::OneSample;
    for (int p = 0; p < pixels; ++p) {
      if (!takesSamples(plan, p)) continue;
      for (int k = 0; k < M; ++k) {
        const int n = plan.counts[size_t(p) * M + k];
        work.slots[k] += oneSample ? passSlots(plan.stageSamples, 1) * n / plan.stageSamples
                                   : passSlots(n, kern::techniqueLeastTurns(k, M));
      }
    }
    return work;
  }
  if (estimator == Estimator::OneSample || groupSize <= 1) {
    for (int p = 0; p < pixels; ++p)
      for (int k = 0; k < M; ++k) work.slots[k] += plan.counts[size_t(p) * M + k];
    return work;
  }
  const std::vector<int32_t> order = coherentPixelOrder(plan, {0, pixels});
  const int launched = int(order.size());
  for (int first = 0; first < launched; first += groupSize)
    for (int k = 0; k < M; ++k) {
      int largest = kern::techniqueLeastTurns(k, M);
      for (int i = first; i < std::min(launched, first + groupSize); ++i)
        largest = std::max(largest, int(plan.counts[size_t(order[i]) * M + k]));
      work.slots[k] += double(groupSize) * largest;
    }
  return work;
}

}  // namespace misalloc
