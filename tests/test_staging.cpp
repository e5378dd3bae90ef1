// The staging of the adaptive methods (render/Render.cpp): a pilot with equal counts,
// then stages whose counts follow the α the samples before them give. Each stage b is
// its own multi-sample balance-heuristic estimate with its own counts, weighted w_b
// (N_b/N, or for the pilot pilotWeight), so the render's variance is
// Σ_b w_b² V(α_b)/N_b with α_b = n_b/N_b the stage's own split ([SHS16] eq. 21 for V).
// The exact variances of the papers' 1D examples compare the unbiased schedules and
// pilot weights considered, and a Monte Carlo run of the staged estimator checks the
// formula.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "BiasCheck.h"
#include "alloc/Apportion.h"
#include "alloc/StageWeights.h"
#include "paper/InverseCdfSampler.h"
#include "paper/MixtureOptimizer.h"
#include "paper/MixtureVariance.h"
#include "paper/PaperExamples.h"
#include "render/Render.h"

using namespace misalloc;

namespace {

using StageCounts = std::vector<std::vector<int>>;  // per stage, the counts n_k

int sampleCount(const std::vector<int>& counts) {
  int n = 0;
  for (int c : counts) n += c;
  return n;
}

// The variance of the staged estimate with the pilot (the first stage) weighted
// `pilotShare` and the stages after it sharing the rest by their sizes; by default
// every stage weighted N_b/N.
double stagedVariance(const Example1D& example, const StageCounts& schedule, double pilotShare = -1) {
  int total = 0;
  for (const auto& counts : schedule) total += sampleCount(counts);
  const int pilot = sampleCount(schedule.front());
  if (pilotShare < 0) pilotShare = double(pilot) / total;
  double v = 0;
  for (size_t b = 0; b < schedule.size(); ++b) {
    const int stage = sampleCount(schedule[b]);
    std::vector<double> alpha;
    for (int n : schedule[b]) alpha.push_back(double(n) / stage);
    double weight = b == 0 ? pilotShare : (1 - pilotShare) * stage / (total - pilot);
    v += weight * weight * multiSampleVariance(example, alpha).value / stage;
  }
  return v;
}

std::vector<int> pilotCounts(int techniques, int pilot) {
  return apportionCounts(std::vector<double>(techniques, 1.0), pilot);
}

// What misalloc does: every stage split by α.
StageCounts proportionalSchedule(const std::vector<double>& alpha, int pilot, const std::vector<int>& stages) {
  StageCounts s{pilotCounts(int(alpha.size()), pilot)};
  for (int size : stages) s.push_back(apportionCounts(alpha, size));
  return s;
}

// The schedule misalloc had before ([HS14] Alg. 1 line 15 read literally): each stage
// takes the deficits max(0, α_k T − m_k), so that the cumulative counts approach α·T.
StageCounts deficitSchedule(const std::vector<double>& alpha, int pilot, const std::vector<int>& stages) {
  StageCounts s{pilotCounts(int(alpha.size()), pilot)};
  std::vector<int> taken = s.front();
  int total = pilot;
  for (int size : stages) {
    total += size;
    std::vector<double> deficit;
    for (size_t k = 0; k < alpha.size(); ++k) deficit.push_back(std::max(0.0, alpha[k] * total - taken[k]));
    s.push_back(apportionCounts(deficit, size));
    for (size_t k = 0; k < alpha.size(); ++k) taken[k] += s.back()[k];
  }
  return s;
}

// The optimum, kept off the simplex's edge by the one-sample-per-technique floor the
// renderer applies, so that every schedule has a finite variance.
std::vector<double> flooredOptimum(const Example1D& example, double floor) {
  std::vector<double> alpha =
      minimiseInefficiency(example, VarianceModel::MultiSample, std::vector<double>(example.techniqueCount(), 1.0))
          .alpha;
  double sum = 0;
  for (double& a : alpha) sum += a = std::max(a, floor);
  for (double& a : alpha) a /= sum;
  return alpha;
}

}  // namespace

TEST_CASE("splitting every stage by alpha beats approaching alpha*N cumulatively", "[adaptive][staging]") {
  // The example: a pilot of 20/20, then stages that want α far from equal.
  for (const char* id : {"002-1", "002-2", "003-1", "003-2", "003-3", "003-4"}) {
    Example1D example = paperExample(id);
    std::vector<double> alpha = flooredOptimum(example, 0.01);
    for (std::vector<int> stages : {std::vector<int>{180}, std::vector<int>{45, 45, 45, 45}}) {
      const int pilot = 10 * example.techniqueCount();
      double proportional = stagedVariance(example, proportionalSchedule(alpha, pilot, stages));
      double deficit = stagedVariance(example, deficitSchedule(alpha, pilot, stages));
      INFO(fmt::format("{} with {} stages: V proportional {:.6g}, deficits {:.6g}", id, stages.size(), proportional,
                       deficit));
      CHECK(proportional <= deficit * (1 + 1e-12));
    }
  }
}

TEST_CASE("the pilot's weight from V(equal)/V(alpha) is the best fixed weight of the pilot", "[adaptive][staging]") {
  // pilotWeight against N_0/N (every stage by its size) and 0 (the pilot dropped), both
  // unbiased too, and against a scan of the weight: the variance is a parabola in it.
  for (const char* id : {"002-1", "002-2", "003-1", "003-2", "003-3", "003-4"}) {
    Example1D example = paperExample(id);
    std::vector<double> alpha = flooredOptimum(example, 0.01);
    const int pilot = 10 * example.techniqueCount(), total = 200;
    const StageCounts schedule = proportionalSchedule(alpha, pilot, {total - pilot});
    std::vector<double> split;
    for (int n : schedule.back()) split.push_back(double(n) / (total - pilot));
    const int M = example.techniqueCount();
    const double ratio =
        multiSampleVariance(example, std::vector<double>(M, 1.0 / M)).value / multiSampleVariance(example, split).value;
    const double weighted = stagedVariance(example, schedule, pilotWeight(float(ratio), pilot, total));
    const double bySize = stagedVariance(example, schedule), dropped = stagedVariance(example, schedule, 0.0);
    double scanned = INFINITY;
    for (int i = 0; i <= 1000; ++i) scanned = std::min(scanned, stagedVariance(example, schedule, i / 1000.0));
    INFO(
        fmt::format("{}: V(equal)/V(alpha) {:.4g}; V weighted {:.6g}, by size {:.6g}, pilot dropped {:.6g}, "
                    "best of the scan {:.6g}",
                    id, ratio, weighted, bySize, dropped, scanned));
    CHECK(weighted <= bySize * (1 + 1e-6));
    CHECK(weighted <= dropped * (1 + 1e-6));
    CHECK(weighted <= scanned * (1 + 1e-6));
  }
  CHECK(pilotWeight(1.0f, 10, 200) == 10.0 / 200);
  CHECK(pilotWeight(NAN, 10, 200) == 10.0 / 200);
  CHECK(pilotWeight(INFINITY, 10, 200) == 0.0);
}

TEST_CASE("the staged estimator's variance is the sum of its stages' exact variances", "[adaptive][staging]") {
  // [SS23] Example 2 (two Gaussians): a pilot of 4 + 4 and one stage of 32 at α = (0.8, 0.2),
  // combined with weights N_b/N, repeated 20000 times with fixed seeds.
  Example1D example = paperExample("003-2");
  const StageCounts schedule{{4, 4}, {26, 6}};
  std::vector<InverseCdfSampler> samplers;
  for (int k = 0; k < 2; ++k) samplers.emplace_back(example.pdf(k));
  std::mt19937_64 rng(2024);
  auto uniform = [&] { return double(rng() >> 11) * 0x1.0p-53; };
  const int runs = 20000, total = 40;
  double sum = 0, sum2 = 0, sum4 = 0;
  std::vector<double> estimates;
  for (int r = 0; r < runs; ++r) {
    double estimate = 0;
    for (const auto& counts : schedule) {
      const int stage = counts[0] + counts[1];
      const std::vector<double> alpha{double(counts[0]) / stage, double(counts[1]) / stage};
      for (int k = 0; k < 2; ++k)
        for (int j = 0; j < counts[k]; ++j) {
          double x = samplers[k].sample(uniform());
          // [HS14] eq. 4.1: f / (N_b p_α), weighted N_b/N.
          estimate += example.f(x) / (stage * example.mixturePdf(alpha, x)) * stage / total;
        }
    }
    estimates.push_back(estimate);
    sum += estimate;
  }
  const double mean = sum / runs;
  for (double e : estimates) {
    double d = (e - mean) * (e - mean);
    sum2 += d;
    sum4 += d * d;
  }
  const double variance = sum2 / (runs - 1);
  // The sample variance's standard error from the fourth central moment.
  const double standardError = std::sqrt((sum4 / runs - variance * variance) / runs);
  // 20000 runs detect a bias of 6 % in the variance and of 0.3 % in the mean.
  misalloc::test::BiasFamily family(0.06, 2);
  family.add("sample variance against stagedVariance", variance, stagedVariance(example, schedule), standardError);
  family.add("mean against the integral", mean, example.integral(), std::sqrt(variance / runs));
  misalloc::test::checkFamily(family);
}
