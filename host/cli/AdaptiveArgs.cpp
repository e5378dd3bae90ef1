#include "cli/AdaptiveArgs.h"

#include <fmt/format.h>

#include <climits>
#include <cmath>

#include "Error.h"
#include "OptionRange.h"
#include "sampling/CostModel.h"

namespace misalloc {
namespace {

GridRule parseGridRule(const std::string& name) {
  if (name == "variance") return GridRule::MinCostVariance;
  if (name == "entropy") return GridRule::MaxEntropy;
  throw InputError(fmt::format("--grid-rule '{}': expected variance or entropy", name));
}

ZeroWeightRule parseLinearRule(const std::string& name) {
  if (name == "variance") return ZeroWeightRule::MinSampleVariance;
  if (name == "drop") return ZeroWeightRule::DropMostNegative;
  throw InputError(fmt::format("--linear-rule '{}': expected variance ([SS23] eq. 19) or drop", name));
}

}  // namespace

void AdaptiveArgs::add(CLI::App& command) {
  command
      .add_option(
          "--pilot", options.pilotFraction,
          "adaptive methods: the pilot's share of the budget, raised for exact to 8 samples per technique within "
          "an eighth of it, for heuristic, sigma-sqrt-c and linear to whole passes of 16 per technique within a "
          "quarter")
      ->capture_default_str()
      ->check(realIn(0, 1, true, true));
  command.add_option("--stages", options.stages, "adaptive methods: stages after the pilot")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  command
      .add_option("--pool", options.poolRadius,
                  "adaptive methods: allocate from the statistics of the (2R+1)^2 pixels around each pixel "
                  "(exact: without the pixel itself, whose pilot is then weighted by the gain its neighbours predict)")
      ->capture_default_str()
      ->check(integerIn(0, 1 << 12));
  command
      .add_option("--skip-below", options.minGain,
                  "exact: keep equal counts where the predicted gain of adapting is below this fraction")
      ->capture_default_str()
      ->check(realIn(0, 1, false, true));
  command
      .add_option("--skip-image-below", options.imageGainBelow,
                  "exact: keep equal counts for the whole image where the pilot predicts a gain at equal time below "
                  "this (0: never)")
      ->capture_default_str()
      ->check(realIn(0, INFINITY, false, true));
  command
      .add_option("--cost", costList,
                  "adaptive methods: cached (the calibration cached for this device, kernel build and scene, made "
                  "once), measure (calibrated again, and cached), or c1,c2[,c3] (cost per sample of each technique)")
      ->capture_default_str();
  command.add_option("--linear-rule", linearRule, "linear: negative weights by variance ([SS23] eq. 19) or drop")
      ->capture_default_str();
  // α is a float: beyond 2^24 combinations, neighbouring weights would coincide.
  command.add_option("--grid-u", options.gridSize, "exact, oracle: number U of weight combinations searched")
      ->capture_default_str()
      ->check(integerIn(2, 1 << 24));
  command
      .add_option("--grid-rule", gridRule,
                  "exact: select by minimum cost x variance (variance) or maximum entropy (entropy, [HS14] Alg. 1)")
      ->capture_default_str();
  command.add_option("--oracle-spp", options.oracleSamples, "oracle: probe samples per pixel")
      ->capture_default_str()
      ->check(integerIn(2, INT_MAX));
  // The kernel unrolls the candidate loop: M is compiled in.
  command.add_option("--ris-candidates", options.risCandidates, "ris: envmap candidates resampled per sample")
      ->capture_default_str()
      ->check(integerIn(1, kMaxRisCandidates));
}

AdaptiveOptions AdaptiveArgs::make(int techniqueCount) const {
  AdaptiveOptions o = options;
  o.linearRule = parseLinearRule(linearRule);
  o.gridRule = parseGridRule(gridRule);
  o.measureCosts = costList == "measure";
  if (costList != "cached" && !o.measureCosts) o.costs = parseCosts(costList, techniqueCount);
  return o;
}

}  // namespace misalloc
