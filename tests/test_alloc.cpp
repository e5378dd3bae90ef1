// The allocation rules of host/alloc on hand-made sums and samples. The numeric
// oracles are the papers' numbers as recomputed independently with high-precision
// quadrature (host/paper/PublishedValues.cpp; docs/papers.md), each labelled in a comment
// by its example and quantity.
#include <catch2/catch.hpp>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "alloc/Allocation.h"
#include "alloc/Apportion.h"
#include "alloc/HeuristicAllocation.h"
#include "alloc/LinearAllocation.h"
#include "alloc/SigmaAllocation.h"
#include "stats/PixelSamples.h"
#include "stats/PixelStats.h"

using namespace misalloc;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

bool onSimplex(const std::vector<double>& alpha) {
  double sum = 0;
  for (double a : alpha) {
    if (!(std::isfinite(a) && a >= 0)) return false;
    sum += a;
  }
  return std::abs(sum - 1) < 1e-12;
}

// Two techniques on [0, 1]: p_0 = 1 (uniform), p_1 = 2x; f is given per test. Samples
// are drawn by inversion with a fixed seed.
PixelSamples twoTechniqueSamples(double (*f)(double), int perTechnique, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  PixelSamples samples(2);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < perTechnique; ++j) {
      double u = uniform(rng), x = k == 0 ? u : std::sqrt(u);
      double pdfs[2] = {1.0, 2 * x};
      samples.add(k, f(x), pdfs);
    }
  return samples;
}

// Three techniques on [0, 1]: uniform, 2x and 3x².
PixelSamples threeTechniqueSamples(double (*f)(double), int perTechnique, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  PixelSamples samples(3);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < perTechnique; ++j) {
      double u = uniform(rng);
      double x = k == 0 ? u : k == 1 ? std::sqrt(u) : std::cbrt(u);
      double pdfs[3] = {1.0, 2 * x, 3 * x * x};
      samples.add(k, f(x), pdfs);
    }
  return samples;
}

}  // namespace

TEST_CASE("sampleVariance is the unbiased estimate of [HS14] eq. 6.19 and never negative", "[alloc]") {
  CHECK(sampleVariance(6, 14, 3) == Approx(1.0).epsilon(1e-15));  // values 1, 2, 3
  CHECK(sampleVariance(5, 25, 1) == 0);                           // one sample: undefined, reported as 0
  // 0.1 three times: cancellation in Σg² − (Σg)²/n must not produce a negative variance.
  CHECK(sampleVariance(0.1 + 0.1 + 0.1, 0.01 + 0.01 + 0.01, 3) >= 0);
  CHECK(isZeroVariance(sampleVariance(0.3, 0.03, 3), 0.1));
  CHECK_FALSE(isZeroVariance(1e-6, 1.0));
}

TEST_CASE("PixelStats::add accumulates every sum of one sample", "[alloc]") {
  PixelStats stats(3);
  double pdfs[3] = {0.5, 2.0, 1.5};
  REQUIRE(stats.add(1, 3.0, pdfs));
  const TechniqueStats& t = stats.technique[1];
  CHECK(t.count == 1);
  CHECK(t.sumW == Approx(1.5));  // f / p_1
  CHECK(t.sumW2 == Approx(2.25));
  CHECK(t.sumBalance == Approx(0.75));  // f / Σ p
  CHECK(t.sumBalance2 == Approx(0.5625));
  CHECK(t.sumF == 3.0);
  CHECK(t.sumPdf[0] == 0.5);
  CHECK(t.sumPdf[1] == 2.0);
  CHECK(t.sumPdf[2] == 1.5);
  CHECK(stats.technique[0].count == 0);
  CHECK(stats.technique[2].count == 0);
}

TEST_CASE("PixelStats::add rejects samples that would poison the sums", "[alloc]") {
  PixelStats stats(2);
  double ok[2] = {1.0, 1.0}, negative[2] = {-1.0, 1.0}, nan[2] = {kNaN, 1.0}, zeroOwn[2] = {0.0, 1.0};
  CHECK_FALSE(stats.add(0, kNaN, ok));
  CHECK_FALSE(stats.add(0, kInf, ok));
  CHECK_FALSE(stats.add(0, 1.0, negative));
  CHECK_FALSE(stats.add(0, 1.0, nan));
  CHECK_FALSE(stats.add(0, 1.0, zeroOwn));  // f ≠ 0 where the sampling pdf is 0
  CHECK(stats.rejectedCount == 5);
  CHECK(stats.technique[0].count == 0);
  // A failed sample (f = 0, p = 0) is a legitimate zero-valued sample.
  double failed[2] = {0.0, 0.0};
  CHECK(stats.add(0, 0.0, failed));
  CHECK(stats.technique[0].count == 1);
  CHECK(stats.technique[0].sumW == 0);
  CHECK(stats.isFinite());
  CHECK_THROWS_AS(stats.add(2, 1.0, ok), std::out_of_range);
  CHECK_THROWS_AS(PixelStats(0), std::invalid_argument);
  CHECK_THROWS_AS(PixelStats(kMaxTechniques + 1), std::invalid_argument);
}

TEST_CASE("allocateEqual gives 1/M", "[alloc]") {
  Allocation a = allocateEqual(4);
  CHECK(a.alpha == std::vector<double>(4, 0.25));
  CHECK_FALSE(a.usedFallback());
}

TEST_CASE("heuristicWeights reproduces [HS14] App. C (eq. 4.17 and eq. 4.20)", "[alloc]") {
  // verified value [HS14] appendix_C "V1", "V2", "V3" (s2 = 8.764) and
  // "alpha heuristic eq.4.17", "H({V1,V2,V3})".
  std::vector<double> v = {29.79279018, 23.4827951, 123.8956154};
  CHECK(harmonicMean(v) == Approx(35.62063444).epsilon(1e-8));
  Allocation a = heuristicWeights(v, {1, 1, 1});
  CHECK(a.alpha[0] == Approx(0.3985375234).epsilon(1e-8));
  CHECK(a.alpha[1] == Approx(0.5056274078).epsilon(1e-8));
  CHECK(a.alpha[2] == Approx(0.09583506872).epsilon(1e-8));
  CHECK_FALSE(a.usedFallback());
  // "alpha cost heuristic eq.4.20": exact s2, V2 = "V2_exact_s2", costs 1, 6.24, 3.28.
  Allocation c = heuristicWeights({29.79279018, 23.49208091, 123.8956154}, {1, 6.24, 3.28});
  CHECK(c.alpha[0] == Approx(0.7833606941).epsilon(1e-8));
  CHECK(c.alpha[1] == Approx(0.1592087297).epsilon(1e-8));
  CHECK(c.alpha[2] == Approx(0.05743057623).epsilon(1e-7));
}

TEST_CASE("heuristicWeights takes [HS14]'s limits for zero and infinite variances", "[alloc]") {
  Allocation infinite = heuristicWeights({4.09963, 35.3278, kInf}, {1, 1, 1});
  CHECK(infinite.alpha[2] == 0);
  CHECK(onSimplex(infinite.alpha));
  // verified value [SHS16] example3 "alpha ~ 1/V[G]": the correct limit is [0.89602, 0.10398, 0.0].
  CHECK(infinite.alpha[0] == Approx(0.89602).epsilon(1e-5));
  CHECK_FALSE(infinite.usedFallback());

  Allocation zero = heuristicWeights({0.0, 2.0, 0.0}, {1, 1, 3});
  CHECK(zero.alpha == std::vector<double>{0.75, 0.0, 0.25});
  CHECK(zero.fallbacks == kFallbackZeroVariance);

  Allocation allInfinite = heuristicWeights({kInf, kInf}, {1, 1});
  CHECK(allInfinite.alpha == std::vector<double>{0.5, 0.5});
  CHECK(allInfinite.fallbacks == kFallbackInfiniteVariance);

  CHECK_THROWS_AS(heuristicWeights({1.0, -1.0}, {1, 1}), std::invalid_argument);
  CHECK_THROWS_AS(heuristicWeights({1.0, kNaN}, {1, 1}), std::invalid_argument);
}

TEST_CASE("costs must be finite and positive, one per technique", "[alloc]") {
  PixelSamples samples = twoTechniqueSamples([](double x) { return x; }, 10, 1);
  for (std::vector<double> bad : {std::vector<double>{1, 0}, {1, -2}, {1, kNaN}, {1, kInf}, {1}, {1, 1, 1}}) {
    CHECK_THROWS_AS(validateCosts(bad, 2), std::invalid_argument);
    CHECK_THROWS_AS(allocateHeuristic(samples.stats(), bad), std::invalid_argument);
    CHECK_THROWS_AS(allocateSigmaSqrtC(samples.stats(), bad), std::invalid_argument);
  }
  CHECK_THROWS_WITH(validateCosts({1, 0}, 2), Catch::Contains("technique 1") && Catch::Contains("> 0"));
  CHECK_NOTHROW(validateCosts({1, 1000}, 2));
}

TEST_CASE("a cost ratio of 1:1000 scales the weights as the formulas say", "[alloc]") {
  PixelSamples samples = twoTechniqueSamples([](double x) { return x * x; }, 200, 7);
  const PixelStats& stats = samples.stats();
  std::vector<double> costs = {1, 1000};

  Allocation h = allocateHeuristic(stats, costs), h1 = allocateHeuristic(stats);
  REQUIRE(onSimplex(h.alpha));
  REQUIRE(h.alpha[1] > 0);
  // [HS14] eq. 4.20: α_k ∝ 1/(c_k V_k), so the cost divides the weight ratio by 1000.
  CHECK(h.alpha[0] / h.alpha[1] == Approx(1000 * h1.alpha[0] / h1.alpha[1]).epsilon(1e-10));

  Allocation s = allocateSigmaSqrtC(stats, costs), s1 = allocateSigmaSqrtC(stats);
  REQUIRE(onSimplex(s.alpha));
  // [SHS16] eq. 31: n_i ∝ σ_i/√c_i.
  CHECK(s.alpha[0] / s.alpha[1] == Approx(std::sqrt(1000.0) * s1.alpha[0] / s1.alpha[1]).epsilon(1e-10));
}

TEST_CASE("sigmaSqrtCWeights follows [SHS16] eq. 31 and falls back when every sigma is 0", "[alloc]") {
  Allocation a = sigmaSqrtCWeights({1.0, 2.0, 3.0}, {1, 4, 9});
  CHECK(a.alpha[0] == Approx(1.0 / 3));
  CHECK(a.alpha[1] == Approx(1.0 / 3));
  CHECK(a.alpha[2] == Approx(1.0 / 3));
  Allocation zero = sigmaSqrtCWeights({0.0, 0.0}, {1, 1});
  CHECK(zero.alpha == std::vector<double>{0.5, 0.5});
  CHECK(zero.fallbacks == kFallbackZeroVariance);
  CHECK_THROWS_AS(sigmaSqrtCWeights({1.0, kNaN}, {1, 1}), std::invalid_argument);
}

TEST_CASE("an equal-valued pilot gives a zero variance estimate, not 0/0", "[alloc]") {
  // f = 1 = p_0: technique 0's estimator f/p_0 is constant, so V_0 = 0 and, by [HS14]'s
  // limit V_k → 0, it takes all the weight.
  PixelSamples samples = twoTechniqueSamples([](double) { return 1.0; }, 50, 3);
  Allocation h = allocateHeuristic(samples.stats());
  CHECK(h.alpha == std::vector<double>{1.0, 0.0});
  CHECK(h.fallbacks & kFallbackZeroVariance);

  // f = p_0 + p_1: f/Σp = 1 for every sample, so every σ_i of [SHS16] eq. 28 is 0.
  PixelSamples sum = twoTechniqueSamples([](double x) { return 1 + 2 * x; }, 50, 3);
  Allocation s = allocateSigmaSqrtC(sum.stats());
  CHECK(s.alpha == std::vector<double>{0.5, 0.5});
  CHECK(s.fallbacks == kFallbackZeroVariance);
  // The linear heuristic is exact for a mixture integrand ([SS23] Sec. 7): f = 2 p_α, α = 1/2.
  for (ZeroWeightRule rule : {ZeroWeightRule::DropMostNegative, ZeroWeightRule::MinSampleVariance}) {
    Allocation l = allocateLinear(sum, rule);
    CHECK(l.alpha[0] == Approx(0.5).epsilon(1e-12));
    CHECK(l.alpha[1] == Approx(0.5).epsilon(1e-12));
    CHECK_FALSE(l.usedFallback());
  }
}

TEST_CASE("a technique whose samples are all zero gets weight 0 in every rule, flagged", "[alloc]") {
  // f vanishes on [0, 1/2), and technique 1 only samples there.
  PixelSamples samples(2);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int j = 0; j < 100; ++j) {
    double x0 = uniform(rng);
    double f0 = x0 >= 0.5 ? x0 : 0.0;
    double pdfs0[2] = {1.0, x0 < 0.5 ? 2.0 : 0.0}, pdfs1[2] = {1.0, 2.0};
    samples.add(0, f0, pdfs0);
    samples.add(1, 0.0, pdfs1);
  }
  const PixelStats& stats = samples.stats();
  for (Allocation a : {allocateHeuristic(stats), allocateSigmaSqrtC(stats), allocateLinear(stats),
                       allocateLinear(samples, ZeroWeightRule::MinSampleVariance)}) {
    CHECK(a.alpha == std::vector<double>{1.0, 0.0});
    CHECK(a.fallbacks & kFallbackSilentTechnique);
  }
}

TEST_CASE("unusable sums fall back to equal weights with the reason", "[alloc]") {
  PixelSamples dark = twoTechniqueSamples([](double) { return 0.0; }, 20, 5);
  for (Allocation a : {allocateHeuristic(dark.stats()), allocateSigmaSqrtC(dark.stats()), allocateLinear(dark.stats()),
                       allocateLinear(dark)}) {
    CHECK(a.alpha == std::vector<double>{0.5, 0.5});
    CHECK(a.fallbacks == kFallbackNoSignal);
  }

  PixelSamples one = twoTechniqueSamples([](double x) { return x; }, 1, 5);
  CHECK(allocateHeuristic(one.stats()).fallbacks == kFallbackTooFewSamples);
  CHECK(allocateSigmaSqrtC(one.stats()).fallbacks == kFallbackTooFewSamples);
  CHECK_FALSE(allocateLinear(one.stats()).usedFallback());  // sums need only one sample each
  CHECK(allocateLinear(PixelStats(2)).fallbacks == kFallbackTooFewSamples);

  PixelStats broken = twoTechniqueSamples([](double x) { return x; }, 20, 5).stats();
  broken.technique[1].sumW2 = kNaN;
  for (Allocation a : {allocateHeuristic(broken), allocateSigmaSqrtC(broken), allocateLinear(broken)}) {
    CHECK(a.alpha == std::vector<double>{0.5, 0.5});
    CHECK(a.fallbacks == kFallbackNonFinite);
  }
}

TEST_CASE("[SS23] eq. 17 and the general eq. 14 solver agree for two techniques", "[alloc]") {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    PixelSamples samples = twoTechniqueSamples([](double x) { return std::exp(x) + std::sin(3 * x); }, 30, seed);
    std::optional<double> closed = linearPairWeight(samples.stats(), 0, 1);
    std::optional<std::vector<double>> general = solveLinearSystem(samples.stats(), 0b11);
    REQUIRE(closed);
    REQUIRE(general);
    CHECK((*general)[0] == Approx(*closed).epsilon(1e-12));
    CHECK((*general)[1] == Approx(1 - *closed).epsilon(1e-12));
  }
}

TEST_CASE("the linear heuristic recovers a mixture integrand exactly for M = 3", "[alloc]") {
  // f = 0.2·1 + 0.5·2x + 0.3·3x² = p_α with α = (0.2, 0.5, 0.3): eq. 14 holds exactly there.
  PixelSamples samples = threeTechniqueSamples([](double x) { return 0.2 + x + 0.9 * x * x; }, 40, 9);
  Allocation a = allocateLinear(samples);
  CHECK(a.alpha[0] == Approx(0.2).epsilon(1e-10));
  CHECK(a.alpha[1] == Approx(0.5).epsilon(1e-10));
  CHECK(a.alpha[2] == Approx(0.3).epsilon(1e-10));
  CHECK(a.zeroedWeights == 0);
}

TEST_CASE("[SS23] Sec. 5.1: both zero-weight techniques return a feasible boundary solution", "[alloc]") {
  // f = x⁴ is steeper than every technique: the raw eq. 14 solution has negative weights.
  PixelSamples samples = threeTechniqueSamples([](double x) { return x * x * x * x; }, 100, 21);
  std::optional<std::vector<double>> raw = solveLinearSystem(samples.stats(), 0b111);
  REQUIRE(raw);
  REQUIRE(*std::min_element(raw->begin(), raw->end()) < 0);

  Allocation first = allocateLinear(samples, ZeroWeightRule::DropMostNegative);
  Allocation second = allocateLinear(samples, ZeroWeightRule::MinSampleVariance);
  CHECK(first.alpha == allocateLinear(samples.stats()).alpha);
  for (const Allocation& a : {first, second}) {
    CHECK(onSimplex(a.alpha));
    CHECK(a.zeroedWeights >= 1);
    CHECK_FALSE(a.usedFallback());
    CHECK(a.alpha[2] > 0.5);
  }
  // The second technique picks the smallest eq. 19 variance among the feasible solutions
  // with as many weights as possible, so it can only improve on a feasible single zero.
  for (int zero = 0; zero < 3; ++zero) {
    unsigned mask = 0b111 & ~(1u << zero);
    std::optional<std::vector<double>> candidate = solveLinearSystem(samples.stats(), mask);
    if (!candidate || *std::min_element(candidate->begin(), candidate->end()) < 0) continue;
    if (second.zeroedWeights == 1)
      CHECK(mixtureSampleVariance(samples, second.alpha) <= mixtureSampleVariance(samples, *candidate) + 1e-15);
  }
}

TEST_CASE("mixtureSampleVariance is [SS23] eq. 19", "[alloc]") {
  PixelSamples samples(2);
  double a[2] = {1.0, 3.0}, b[2] = {2.0, 2.0}, c[2] = {4.0, 0.0};
  samples.add(0, 2.0, a);
  samples.add(0, 4.0, b);
  samples.add(1, 1.0, c);
  samples.add(1, 1.0, a);
  std::vector<double> alpha = {0.5, 0.5};
  // p_α: sample 1: 2, sample 2: 2, sample 3: 2, sample 4: 2. Ratios f/p: 1, 2 | 0.5, 0.5.
  double expected = 0.5 * ((1 + 4) / 2.0 - 1.5 * 1.5) + 0.5 * (0.25 - 0.25);
  CHECK(mixtureSampleVariance(samples, alpha) == Approx(expected).epsilon(1e-15));
  // A technique with α_i = 0 contributes nothing.
  CHECK(mixtureSampleVariance(samples, {1.0, 0.0}) == Approx(0.25 * 1 * ((4 + 4) / 2.0 - 4)).margin(1e-15));
}

TEST_CASE("apportionCounts sums exactly to N by largest remainder", "[alloc]") {
  CHECK(apportionCounts({1.0 / 3, 1.0 / 3, 1.0 / 3}, 100) == std::vector<int>{34, 33, 33});
  CHECK(apportionCounts({0.5, 0.5}, 0) == std::vector<int>{0, 0});
  CHECK(apportionCounts({2.0, 6.0}, 4) == std::vector<int>{1, 3});  // normalised first
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial) {
    std::vector<double> alpha(1 + trial % 4);
    for (double& a : alpha) a = uniform(rng) < 0.2 ? 0.0 : uniform(rng);
    if (std::accumulate(alpha.begin(), alpha.end(), 0.0) == 0) alpha[0] = 1;
    int total = static_cast<int>(uniform(rng) * 1000);
    std::vector<int> counts = apportionCounts(alpha, total);
    double sum = std::accumulate(alpha.begin(), alpha.end(), 0.0);
    REQUIRE(std::accumulate(counts.begin(), counts.end(), 0) == total);
    for (std::size_t k = 0; k < alpha.size(); ++k) {
      REQUIRE(counts[k] >= 0);
      REQUIRE(std::abs(counts[k] - alpha[k] / sum * total) < 1);
    }
  }
  CHECK_THROWS_AS(apportionCounts({0.5, -0.1}, 10), std::invalid_argument);
  CHECK_THROWS_AS(apportionCounts({0.0, 0.0}, 10), std::invalid_argument);
  CHECK_THROWS_AS(apportionCounts({kNaN, 1.0}, 10), std::invalid_argument);
  CHECK_THROWS_AS(apportionCounts({1.0}, -1), std::invalid_argument);
}
