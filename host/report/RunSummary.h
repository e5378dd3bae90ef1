#pragma once
// What every report of one render says of it (render's JSON report, compare's runs),
// computed in one place.
#include <optional>
#include <vector>

#include "render/Reference.h"
#include "render/Render.h"
#include "report/ImageMetrics.h"

namespace misalloc {

struct RunSummary {
  std::vector<double> meanAlpha;  // per technique: its share of the samples, mean over pixels
  double fallbackFraction = 0;    // pixels where an allocation rule fell back
  double flooredFraction = 0;     // pixels whose counts the floor raised to one per technique
  double skippedFraction = 0;     // pixels the skip rule kept at equal weights
  double weightsFallbackFraction = 0;  // --weights optimal: pixels a stage left at the balance heuristic
  // Against the reference, where there is one: raw, and corrected for its own variance.
  std::optional<double> mse, relativeMse;
  std::optional<CorrectedMse> corrected;
};

RunSummary summarizeRun(const Rendering& rendering, int techniqueCount, const Reference* reference);

}  // namespace misalloc
