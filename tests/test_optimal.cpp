// The optimal envmap pdf of [Kar19] eq. 9 and its bank (host/distributions/OptimalBank.h):
// λ's bisection within eq. 10 on stiff cases, the binning of the grid's BRDFs, the
// entry a stage samples with, and what the bank's tables hold. Its sampler and
// unbiasedness are tested with the other pdfs' (test_envmap.cpp, test_compensated.cpp,
// test_sampler.cpp).
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "KernelCode.h"
#include "SceneFixtures.h"
#include "distributions/CompensatedPdf.h"
#include "distributions/OptimalBank.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

struct Nodes {
  std::vector<double> f, q, w;
  double F = 0;
};

// n nodes of weight 1/n: a sky of radiance 1 with one node of a sun `sun` times
// brighter, seen through a lobe that puts `lobeShare` of the BRDF pdf on node `peak`
// and spreads the rest evenly; q = (1−c) p_ρ, f = L p_ρ (an ideal BRDF sampler).
Nodes stiffCase(int n, double sun, int sunNode, double lobeShare, int peak, double c) {
  Nodes x;
  for (int i = 0; i < n; ++i) {
    const double brdf = (i == peak ? lobeShare : 0.0) + (1 - lobeShare) / n;  // mass per node
    const double pRho = brdf * n;                                             // density
    const double radiance = i == sunNode ? sun : 1.0;
    x.f.push_back(radiance * pRho);
    x.q.push_back((1 - c) * pRho);
    x.w.push_back(1.0 / n);
    x.F += x.w.back() * x.f.back();
  }
  return x;
}

double optimalMass(const Nodes& x, double lambda, double c) {
  double mass = 0;
  for (size_t i = 0; i < x.f.size(); ++i) mass += x.w[i] * optimalFree(x.f[i], x.q[i], lambda, c);
  return mass;
}

}  // namespace

TEST_CASE("eq. 10's bounds bracket the λ of [Kar19] eq. 9, which normalises p*, on stiff cases", "[optimal]") {
  // A 10⁶ sun off a lobe of n = 10⁵ (nearly all of p_ρ on one node), on it, and a
  // 10⁻⁶ sun; every share.
  for (double c : {0.05, 0.25, 0.5, 0.75, 0.95})
    for (double sun : {1e6, 1e-6})
      for (int sunNode : {3, 500}) {
        Nodes x = stiffCase(1000, sun, sunNode, 1 - 1e-5, 500, c);
        OptimalLambda l = solveOptimalLambda(x.f.data(), x.q.data(), x.w.data(), x.f.size(), x.F, c);
        INFO("c " << c << " sun " << sun << " at node " << sunNode << ": lambda " << l.lambda << " in [" << l.lower
                  << ", " << l.upper << "]");
        // Eq. 10 brackets the λ that normalises p*: ∫ p* falls as λ grows, so it is at
        // least 1 at the lower bound and at most 1 at the upper (with rounding's slack).
        CHECK(optimalMass(x, c * x.F * x.F, c) >= 1 - 1e-12);
        CHECK(optimalMass(x, x.F * x.F / c, c) <= 1 + 1e-12);
        CHECK(optimalMass(x, l.lambda, c) == Approx(1).epsilon(1e-9));
      }
}

TEST_CASE("where eq. 5 is nowhere negative, λ is eq. 10's lower bound and eq. 9 is eq. 6", "[optimal]") {
  // f ∝ p_ρ with a bright enough radiance everywhere: f/(cF) − q/c ≥ 0 (Appendix B).
  for (double c : {0.25, 0.5, 0.75}) {
    Nodes x = stiffCase(64, 1.0, 0, 0.5, 10, c);  // constant radiance: f = p_ρ
    OptimalLambda l = solveOptimalLambda(x.f.data(), x.q.data(), x.w.data(), x.f.size(), x.F, c);
    CHECK(l.lambda == Approx(l.lower).epsilon(1e-9));
    for (size_t i = 0; i < x.f.size(); ++i)
      CHECK(optimalFree(x.f[i], x.q[i], l.lambda, c) == Approx(misCompensated(x.f[i], x.q[i], x.F, c)).epsilon(1e-8));
  }
}

TEST_CASE("the grid's BRDFs fall in the nearest of log-spaced exponent bins and diffuse-weight bins", "[optimal]") {
  SECTION("one BRDF: one bin, its own parameters") {
    const BrdfBins bins = binBrdfs(makeBrdfGrid("uniform:0.3,0.6,50", 4, 4), 8, 2);
    REQUIRE(bins.centres.size() == 1);
    CHECK(bins.centres[0].n == Approx(50));
    CHECK(bins.centres[0].rhoD == Approx(1.0 / 3));
    CHECK(bins.centres[0].rhoS == Approx(2.0 / 3));
    for (int b : bins.binOfPixel) CHECK(b == 0);
  }
  SECTION("one bin over a range: its centre is the middle of the range") {
    const BrdfGrid grid = makeBrdfGrid("general:0.2,0.6,4,400", 8, 8);
    const BrdfBins bins = binBrdfs(grid, 1, 1);
    REQUIRE(bins.centres.size() == 1);
    CHECK(bins.centres[0].n == Approx(40).epsilon(1e-4));  // √(4 · 400)
    CHECK(bins.centres[0].rhoD == Approx(0.4).epsilon(1e-4));
  }
  SECTION("seed000: every pixel within half a bin of its centre") {
    const BrdfGrid grid = makeBrdfGrid("seed000", 64, 64);
    const BrdfBins bins = binBrdfs(grid, 8, 2);
    CHECK(bins.centres.size() == 16);
    double lo = 1e300, hi = 0;
    for (const PhongParameters& p : grid.pixels) lo = std::min(lo, double(p.n)), hi = std::max(hi, double(p.n));
    const double halfBin = 0.5 * std::log(hi / lo) / 8;
    for (size_t p = 0; p < grid.pixels.size(); ++p) {
      const PhongParameters& centre = bins.centres[bins.binOfPixel[p]];
      CHECK(std::abs(std::log(double(grid.pixels[p].n) / centre.n)) <= halfBin * (1 + 1e-5));
      const double wd = grid.pixels[p].rhoD / (grid.pixels[p].rhoD + grid.pixels[p].rhoS);
      CHECK(std::abs(wd - centre.rhoD) <= 0.25 + 1e-6);  // two bins over the weights' range, at most [0, 1]
    }
  }
}

TEST_CASE("a stage samples with the entry of the share nearest its envmap fraction", "[optimal]") {
  kern::EnvmapView env{};
  env.bankShares = 3;
  env.brdfBin = 5;
  for (int i = 0; i < 3; ++i) CHECK(kern::bankEntryOf(env, float(bankShare(i, 3))) == 15 + i);
  CHECK(kern::bankEntryOf(env, 0.0f) == 15);
  CHECK(kern::bankEntryOf(env, 0.37f) == 15);  // nearer 1/4 than 1/2
  CHECK(kern::bankEntryOf(env, 0.38f) == 16);
  CHECK(kern::bankEntryOf(env, 1.0f) == 17);
  CHECK(bankShare(1, 3) == 0.5);  // equal counts of M = 2 get C = 1/2
}

TEST_CASE("the bank's eq. 9 is never worse than eq. 6, and equals it where eq. 5 stays positive", "[optimal]") {
  SECTION("a real map and seed000: eq. 5 goes negative, eq. 6 costs more") {
    const Scene scene = smallScene("rooitou_park", "seed000", 16, 16, false, EnvmapSampler::Alias, 0, "optimal");
    const BankVariances& v = scene.tables.bankVariances;
    CHECK(v.entriesWithNegativeEq5 > 0);
    CHECK(v.compensatedOverOptimalMean >= 1 - 1e-9);
    CHECK(v.compensatedOverOptimalMax > 1.01);
  }
  SECTION("a constant map under a diffuse BRDF sampled by its own cosine: f ∝ p_ρ") {
    const Scene scene = smallScene("constant", "uniform:1,0,1", 4, 4, false, EnvmapSampler::Alias, 0, "optimal");
    const BankVariances& v = scene.tables.bankVariances;
    CHECK(v.entriesWithNegativeEq5 == 0);
    CHECK(v.compensatedOverOptimalMax == Approx(1).epsilon(1e-6));
  }
  SECTION("a 10⁶ sun and n = 10⁵: finite probabilities that sum to 1") {
    for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
      const Scene scene =
          smallScene("sun:50,0,0.5,1e6", "uniform:0.05,0.95,100000", 4, 4, false, sampler, 20, "optimal");
      const EnvmapTables& t = scene.tables;
      REQUIRE(t.hasBank());
      const size_t blocks = t.blockProbs.size() / size_t(t.brdfBins * t.bankShares);
      for (int entry = 0; entry < t.brdfBins * t.bankShares; ++entry) {
        double sum = 0;
        for (size_t b = 0; b < blocks; ++b) {
          const float p = t.blockProbs[entry * blocks + b];
          REQUIRE(std::isfinite(p));
          REQUIRE(p >= 0);
          sum += p;
        }
        CHECK(sum == Approx(1).epsilon(1e-5));
      }
    }
  }
}
