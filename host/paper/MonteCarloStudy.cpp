#include "paper/MonteCarloStudy.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "alloc/HeuristicAllocation.h"
#include "alloc/LinearAllocation.h"
#include "alloc/SigmaAllocation.h"
#include "paper/InverseCdfSampler.h"
#include "paper/MixtureVariance.h"

namespace misalloc {

namespace {

// 53 random bits, so the stream does not depend on the standard library's distributions.
double uniform(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

PixelSamples drawPilot(const Example1D& example, const std::vector<InverseCdfSampler>& samplers, int perTechnique,
                       std::mt19937_64& rng) {
  int m = example.techniqueCount();
  PixelSamples samples(m);
  std::vector<double> pdfs(m);
  for (int k = 0; k < m; ++k)
    for (int j = 0; j < perTechnique; ++j) {
      double x = samplers[k].sample(uniform(rng));
      for (int i = 0; i < m; ++i) pdfs[i] = example.pdf(i)(x);
      samples.add(k, example.f(x), pdfs.data());
    }
  return samples;
}

Allocation allocate(AllocationRule rule, const PixelSamples& samples, const std::vector<double>& costs) {
  switch (rule) {
    case AllocationRule::Equal:
      return allocateEqual(samples.techniqueCount());
    case AllocationRule::Heuristic:
      return allocateHeuristic(samples.stats(), costs);
    case AllocationRule::SigmaSqrtC:
      return allocateSigmaSqrtC(samples.stats(), costs);
    case AllocationRule::LinearDropMostNegative:
      return allocateLinear(samples, ZeroWeightRule::DropMostNegative);
    case AllocationRule::LinearMinSampleVariance:
      return allocateLinear(samples, ZeroWeightRule::MinSampleVariance);
  }
  return allocateEqual(samples.techniqueCount());
}

double quantile(const std::vector<double>& sorted, double q) {
  double position = q * (sorted.size() - 1);
  std::size_t below = static_cast<std::size_t>(position);
  if (below + 1 >= sorted.size()) return sorted.back();
  double t = position - below;
  return t == 0 ? sorted[below] : sorted[below] + t * (sorted[below + 1] - sorted[below]);
}

Quantiles quantiles(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  double mean = std::accumulate(values.begin(), values.end(), 0.0) / values.size();
  return {mean, quantile(values, 0.5), quantile(values, 0.1), quantile(values, 0.9)};
}

}  // namespace

std::vector<AllocationRule> allAllocationRules() {
  return {AllocationRule::Equal, AllocationRule::Heuristic, AllocationRule::SigmaSqrtC,
          AllocationRule::LinearDropMostNegative, AllocationRule::LinearMinSampleVariance};
}

std::string allocationRuleName(AllocationRule rule) {
  switch (rule) {
    case AllocationRule::Equal:
      return "equal";
    case AllocationRule::Heuristic:
      return "heuristic ([HS14] eq. 4.20)";
    case AllocationRule::SigmaSqrtC:
      return "sigma/sqrt(c) ([SHS16] eq. 31)";
    case AllocationRule::LinearDropMostNegative:
      return "linear, drop most negative ([SS23])";
    case AllocationRule::LinearMinSampleVariance:
      return "linear, min sample variance ([SS23])";
  }
  return "";
}

std::vector<RuleOutcome> runAllocationStudy(const Example1D& example, const StudyConfig& config) {
  int m = example.techniqueCount();
  std::vector<InverseCdfSampler> samplers;
  for (int k = 0; k < m; ++k) samplers.emplace_back(example.pdf(k));
  std::vector<double> sigmas = countIndependentSigmas(example);
  const std::vector<double>& costs = example.costs();

  std::vector<AllocationRule> rules = allAllocationRules();
  std::vector<RuleOutcome> outcomes;
  std::vector<std::vector<double>> inefficiencies(rules.size());
  for (AllocationRule rule : rules) outcomes.push_back({rule, std::vector<double>(m, 0.0), {}, 0, 0});

  std::mt19937_64 rng(config.seed);
  for (int run = 0; run < config.runs; ++run) {
    PixelSamples samples = drawPilot(example, samplers, config.samplesPerTechnique, rng);
    for (std::size_t r = 0; r < rules.size(); ++r) {
      Allocation a = allocate(rules[r], samples, costs);
      double variance = rules[r] == AllocationRule::SigmaSqrtC ? countIndependentVariance(sigmas, a.alpha)
                                                               : multiSampleVariance(example, a.alpha).value;
      inefficiencies[r].push_back(inefficiency(costs, a.alpha, variance));
      for (int k = 0; k < m; ++k) outcomes[r].meanAlpha[k] += a.alpha[k] / config.runs;
      outcomes[r].fallbackRuns += a.usedFallback();
      outcomes[r].boundaryRuns += a.zeroedWeights > 0;
    }
  }
  for (std::size_t r = 0; r < rules.size(); ++r) outcomes[r].inefficiency = quantiles(inefficiencies[r]);
  return outcomes;
}

}  // namespace misalloc
