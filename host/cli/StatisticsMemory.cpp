#include "cli/StatisticsMemory.h"

#include <fmt/format.h>

#include "MemoryBudget.h"

namespace misalloc {

void requireStatisticsMemory(const SceneOptions& scene, Method m, const std::string& sppOption, int spp,
                             const AdaptiveOptions& adaptive, bool onHost, int samplers) {
  const SamplerConfig config = samplerConfigFor(m, Estimator::MultiSample, spp, adaptive);
  const double pixels = double(scene.width) * scene.height, M = scene.splitBrdf ? 3 : 2;
  if (config.sampleCapacity > 0) {
    // A record of M + 2 floats per sample (kernels/stats.h), on a CPU device once in
    // its buffer and once read back; with several devices, once in each device's
    // buffer, once gathered on the host and once read back.
    const int copies = samplers > 1 ? samplers + 2 : 2;
    const double perPixel = double(config.sampleCapacity) * (M + 2) * sizeof(float) * copies;
    std::string option = fmt::format("{} {}", sppOption, spp);
    if (methodTraits(m).split == Split::Probed) option += fmt::format(" and --oracle-spp {}", adaptive.oracleSamples);
    requireHostMemory(fmt::format("{} with --method {} ({:g} pixels × {} stored samples × {:g} B)", option,
                                  methodName(m), pixels, config.sampleCapacity, (M + 2) * sizeof(float) * copies),
                      pixels * perPixel);
  }
  if (config.gridSize > 0) {
    // The weight grid, M weights and a cost per combination, is built on the host; the
    // running sums, Σ g and Σ g² per technique and combination, too on the C++ device
    // (sampling/GridSearch.h). Both from the options alone: building the grid to size it
    // would be the allocation this check prevents.
    const double U = config.gridSize, gridBytes = U * (M + 1) * sizeof(float);
    const double sumBytes = onHost ? pixels * 2 * M * U * sizeof(float) : 0;
    requireHostMemory(
        fmt::format(
            "--grid-u {} ({:g} combinations × {:g} B{})", config.gridSize, U, (M + 1) * sizeof(float),
            sumBytes > 0 ? fmt::format(", and {:g} pixels × {:g} B of sums", pixels, 2 * M * U * sizeof(float)) : ""),
        gridBytes + sumBytes);
  }
}

}  // namespace misalloc
