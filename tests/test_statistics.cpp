// The shared statistics helper of the distribution tests (tests/Statistics.h).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "Statistics.h"

using namespace misalloc::test;

TEST_CASE("the χ² p-value helper matches tabulated quantiles", "[statistics]") {
  CHECK(upperRegularisedGamma(0.5, 0.5 * 3.841459) == Approx(0.05).epsilon(1e-5));
  CHECK(upperRegularisedGamma(5.0, 0.5 * 18.307038) == Approx(0.05).epsilon(1e-5));
  CHECK(upperRegularisedGamma(50.0, 0.5 * 135.806723) == Approx(0.01).epsilon(1e-5));
  CHECK(upperRegularisedGamma(5000.0, 0.5 * 10000.0) == Approx(0.5).epsilon(1e-2));
}

TEST_CASE("χ² pools the bins that expect fewer than 5 counts", "[statistics]") {
  // Two regular bins and three small ones (expected 1, 2, 3: a pool of 6).
  std::vector<double> p = {0.45, 0.49, 0.01, 0.02, 0.03};
  std::vector<uint64_t> counts = {45, 49, 1, 2, 3};
  ChiSquare exact = chiSquare(counts, p, 100);
  CHECK(exact.degreesOfFreedom == 2);
  CHECK(exact.statistic == Approx(0.0).margin(1e-12));
  CHECK(exact.pValue() == Approx(1.0));
  // A pool still below 5 joins the smallest regular bin: (40 + 2, 58) against (42, 58).
  ChiSquare joined = chiSquare({40, 58, 2}, {0.40, 0.58, 0.02}, 100);
  CHECK(joined.degreesOfFreedom == 1);
  CHECK(joined.statistic == Approx(0.0).margin(1e-12));
  // A far-off sample is rejected.
  CHECK(chiSquare({80, 20}, {0.5, 0.5}, 100).pValue() < 1e-8);
}

TEST_CASE("the Šidák level keeps the family's false-alarm rate", "[statistics]") {
  CHECK(sidakLevel(0.05, 1) == Approx(0.05));
  double level = sidakLevel(0.01, 20);
  CHECK(1 - std::pow(1 - level, 20) == Approx(0.01).epsilon(1e-12));
  CHECK(sidakLevel(0.02, 20) > 1e-3);
}

TEST_CASE("a bias family fails a biased test and an underpowered one, and sizes a test to its power", "[statistics]") {
  BiasFamily family(0.01, 10);
  const double bound = family.bound();  // Šidák over 10 tests at 1e-3
  CHECK(bound == Approx(twoSidedNormalBound(sidakLevel(1e-3, 10))));
  // A standard error that detects exactly 1 %: (bound + z_0.9) · se = 0.01.
  const double se = 0.01 / (bound + kPowerZ);
  family.add("fair", 1.0 + 0.5 * se, 1.0, se);
  CHECK(family.failures().empty());
  CHECK(family.detectable() == Approx(0.01));
  family.add("biased", 1.0 + 1.01 * bound * se, 1.0, se);
  family.add("noisy", 1.0, 1.0, 1.01 * se);
  const std::vector<std::string> failures = family.failures();
  REQUIRE(failures.size() == 2);
  CHECK(failures[0].rfind("biased: biased", 0) == 0);
  CHECK(failures[1].rfind("too few samples", 0) == 0);
  // Four times the error needs 16 times the samples, and the pilot's margin of 1.5.
  const long long samples = family.samplesFor(4 * se, 100, 1.0);
  CHECK(samples >= 2400);
  CHECK(samples <= 2401);
  for (int i = 0; i < 8; ++i) family.add("more", 1.0, 1.0, se);
  CHECK(family.failures().size() == 3);  // 11 tests: more than the bound was set for
}
