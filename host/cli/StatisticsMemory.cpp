#include "cli/StatisticsMemory.h"

#include <fmt/format.h>

#include "KernelCode.h"
#include "MemoryBudget.h"
#include "distributions/OptimalBank.h"

namespace misalloc {
namespace {

struct MemoryNeed {
  std::string what;
  double bytes = 0;
};

// What one method's sampler keeps beyond the render itself.
void appendStatisticsMemory(std::vector<MemoryNeed>& needs, const SceneOptions& scene, Method m,
                            const std::string& sppOption, int spp, const AdaptiveOptions& adaptive, bool onHost,
                            int samplers) {
  const SamplerConfig config = samplerConfigFor(m, Estimator::MultiSample, spp, adaptive, scene.techniqueCount());
  const double pixels = double(scene.width) * scene.height;
  // The columns of every share of an optimal pdf, the bank's or per pixel (sampleColumns),
  // from the options alone: at most what the scene's tables give.
  const int shares = !config.shareColumns             ? 0
                     : scene.envmapPdf.optimal()      ? OptimalBankOptions{}.shares
                     : scene.envmapPdf.pixelOptimal() ? MA_MAX_BANK_SHARES
                                                      : 0;
  const double C = MA_STORED_COLUMNS(scene.techniqueCount(), shares);
  if (config.sampleCapacity > 0) {
    // A record per sample (kernels/stats.h), on a CPU device once in its buffer and
    // once read back; with several devices, once in each device's buffer, once
    // gathered on the host and once read back.
    const int copies = samplers > 1 ? samplers + 2 : 2;
    const double recordBytes = MA_SAMPLE_RECORD_FLOATS(int(C)) * sizeof(float);
    const double perPixel = double(config.sampleCapacity) * recordBytes * copies;
    std::string option = fmt::format("{} {}", sppOption, spp);
    if (methodTraits(m).split == Split::Probed) option += fmt::format(" and --oracle-spp {}", adaptive.oracleSamples);
    needs.push_back({fmt::format("{} with --method {} ({:g} pixels × {} stored samples × {:g} B)", option,
                                 methodName(m), pixels, config.sampleCapacity, recordBytes * copies),
                     pixels * perPixel});
  }
  if (config.gridSize > 0) {
    // The weight grid, a weight per column and a cost per combination, is built on the
    // host; the running sums, Σ g and Σ g² per column and combination (and with optimal
    // weights P's C(C+1)/2 pairs), too on the C++ device where a render searches more
    // than once (alloc/GridSearch.h). Both from the options alone: building the grid to
    // size it would be the allocation this check prevents.
    const double U = config.gridSize, gridBytes = U * (C + 1) * sizeof(float);
    const double rows = 2 * C + (config.optimalWeights ? C * (C + 1) / 2 : 0);
    const double sumBytes = onHost && config.runningSums ? pixels * rows * U * sizeof(float) : 0;
    needs.push_back(
        {fmt::format(
             "--grid-u {} ({:g} combinations × {:g} B{})", config.gridSize, U, (C + 1) * sizeof(float),
             sumBytes > 0 ? fmt::format(", and {:g} pixels × {:g} B of sums", pixels, rows * U * sizeof(float)) : ""),
         gridBytes + sumBytes});
  }
}

}  // namespace

void requireStatisticsMemory(const SceneOptions& scene, const std::vector<Method>& methods,
                             const std::string& sppOption, int spp, const AdaptiveOptions& adaptive, bool onHost,
                             int samplers) {
  std::vector<MemoryNeed> needs;
  for (Method m : methods) appendStatisticsMemory(needs, scene, m, sppOption, spp, adaptive, onHost, samplers);
  if (needs.empty()) return;
  MemoryNeed total = needs.front();
  for (size_t i = 1; i < needs.size(); ++i) {
    total.what += " and " + needs[i].what;
    total.bytes += needs[i].bytes;
  }
  requireHostMemory(total.what, total.bytes);
}

}  // namespace misalloc
