// [Kon19]'s optimal MIS weights (--weights optimal): the kernel's per-sample term
// (kernels/pixel.h, withOptimalWeights) and the partition of unity it implies, the
// normalisation of every pdf it subtracts, the sums and the guarded solve
// (host/alloc/OptimalWeights.h), and renders that use them: unbiased against [HS14]
// eq. 6.17, their fallbacks counted, refused where no multi-sample balance heuristic runs.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <random>
#include <vector>

#include "BiasCheck.h"
#include "CliRunner.h"
#include "Constants.h"
#include "KernelCode.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "alloc/OptimalWeights.h"
#include "paper/OptimalWeightsVariance.h"
#include "paper/PaperExamples.h"
#include "paper/Quadrature.h"
#include "render/Render.h"
#include "render/RunChecks.h"
#include "report/Report.h"
#include "sampling/KernelViews.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

constexpr double kFloatEpsilon = 1.0 / (1 << 24);

// A sample of technique t at a point with pdfs p and value f, as takeTechniqueSample
// leaves it for withOptimalWeights.
kern::SampleContribution sampleAt(int t, const float* p, const float* f, const kern::StageCounts& c) {
  kern::SampleContribution s{};
  s.technique = t;
  float alpha[MA_MAX_TECHNIQUES] = {float(c.n0) / c.stageSamples, float(c.n1) / c.stageSamples,
                                    float(c.n2) / c.stageSamples};
  const float pAlpha = kern::mixturePdf(c.techniqueCount, alpha, p);
  s.invP = 1.0f / pAlpha;
  for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) s.pdfs[k] = p[k];
  s.fr = f[0];
  s.fg = f[1];
  s.fb = f[2];
  return s;
}

kern::StageCounts countsOf(const std::vector<int>& n) {
  kern::StageCounts c{};
  c.techniqueCount = int(n.size());
  c.n0 = n[0];
  c.n1 = n[1];
  c.n2 = n.size() > 2 ? n[2] : 0;
  c.stageSamples = c.n0 + c.n1 + c.n2;
  return c;
}

AdaptiveOptions optimalOptions(int techniqueCount) {
  AdaptiveOptions options;
  options.costs.assign(techniqueCount, 1.0);
  options.weights = MisWeights::Optimal;
  return options;
}

Rendering renderOptimal(const Scene& scene, Method method, int spp, uint64_t seed,
                        MisWeights weights = MisWeights::Optimal) {
  AdaptiveOptions options = optimalOptions(scene.techniqueCount());
  options.weights = weights;
  const auto sampler =
      sweepSampler(scene, samplerConfigFor(method, Estimator::MultiSample, spp, options, scene.techniqueCount()));
  return render(*sampler, method, options, spp, seed);
}

// The running sums of MA_STATS_OPTIMAL over samples of technique t with the given pdfs
// and values, added as the kernels add them (kernels/stats.h).
struct SyntheticSums {
  int M;
  unsigned mask = MA_STATS_OPTIMAL;
  std::vector<double> slots;

  explicit SyntheticSums(int M) : M(M), slots(size_t(M) * MA_STATS_PER_TECHNIQUE(MA_STATS_OPTIMAL, M), 0.0) {}
  void add(const kern::SampleContribution& s) {
    const int perTechnique = MA_STATS_PER_TECHNIQUE(int(mask), M);
    for (int slot = 0; slot < perTechnique; ++slot)
      slots[size_t(s.technique) * perTechnique + slot] += kern::statValue(int(mask), M, slot, s);
  }
  OptimalWeightsSystem system() const { return optimalWeightsSystem(slots.data(), mask, M); }
};

}  // namespace

TEST_CASE("the optimal weights' w_k sum to 1 at random points, for random coefficients", "[weights]") {
  // A sample of technique t adds w_t f/(n_t p_t) (kernels/pixel.h): recovering each
  // w_t from that term at the same point, Σ_t w_t = 1 ([Kon19]), whatever a is. Float
  // rounding scales with the terms that cancel, Σ_l |a_l| p_l against f.
  std::mt19937 rng(2019);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), coefficient(-4.0f, 4.0f);
  int failures = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const int M = 2 + trial % 2;
    std::vector<int> n(M);
    for (int& k : n) k = 1 + int(unit(rng) * 40);
    const kern::StageCounts c = countsOf(n);
    float p[MA_MAX_TECHNIQUES] = {}, f[3];
    for (int k = 0; k < M; ++k) p[k] = std::exp2(20.0f * unit(rng) - 10.0f);
    for (float& v : f) v = 0.01f + 10.0f * unit(rng);
    kern::OptimalCoefficients a{};
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 0; k < M; ++k) a.a[ch][k] = coefficient(rng) * f[ch] / (M * p[k]);
    double sum[3] = {0, 0, 0}, cancelling[3] = {0, 0, 0};
    for (int t = 0; t < M; ++t) {
      const kern::SampleContribution s = kern::withOptimalWeights(sampleAt(t, p, f, c), c, a);
      const float term[3] = {s.r, s.g, s.b};
      for (int ch = 0; ch < 3; ++ch) {
        sum[ch] += double(term[ch]) * n[t] * p[t] / f[ch];
        cancelling[ch] += std::abs(a.a[ch][t]) * p[t];
      }
    }
    for (int ch = 0; ch < 3; ++ch)
      failures += !(std::abs(sum[ch] - 1) <= 64 * kFloatEpsilon * (1 + 2 * cancelling[ch] / f[ch]));
  }
  CHECK(failures == 0);
}

TEST_CASE("with coefficients 0 the optimal weights' kernel is the balance heuristic's, bit for bit", "[weights]") {
  for (bool split : {false, true}) {
    const Scene scene = smallScene("venice_sunset", "seed000", 24, 16, split);
    SamplerConfig balance, optimal;
    optimal.optimalWeights = true;
    optimal.statsMask = MA_STATS_OPTIMAL;
    const StagePlan plan = singleStagePlan(scene, Method::Equal, 40);
    StageResult a = Sampler(testDevice(), scene, balance).run(plan, 3);
    StageResult b = Sampler(testDevice(), scene, optimal).run(plan, 3);
    CHECK(a.rgb == b.rgb);
    CHECK(a.moments == b.moments);
  }
}

TEST_CASE("every pdf the optimal weights subtract integrates to 1 over the sphere, where f = 0 too", "[weights]") {
  // Σ_k a_k ∫ p_k = Σ_k a_k needs each p_k, as the kernels evaluate it, to integrate to 1
  // over the whole sphere: the Phong lobe below the horizon (f = 0 there, and its
  // samples count) and the envmap's zero texels included. Midpoint quadrature about the
  // mirror direction, with 1 − cos α = 2t⁴ so that a lobe of n = 10⁴ is resolved.
  // 3000 rings in both sizes: with 1500 the diffuse pdf at a view of 89°, whose horizon
  // cuts through the rings, sums to 1 + 1.8e-5, the quadrature's error, not the pdf's.
  const int nt = 3000, nphi = 384;
  const std::vector<double> views = {0.0, 60.0, 89.0};
  const std::vector<double> exponents = smallTestSize() ? std::vector<double>{1, 1e4} : std::vector<double>{1, 30, 1e4};
  for (double view : views)
    for (double n : exponents) {
      const double theta = view * kPi / 180;
      const kern::MaVec3 mirror = kern::makeVec3(float(std::sin(theta)), 0.0f, float(std::cos(theta)));
      kern::PhongParams b{0.3f, 0.7f, float(n)};
      const kern::MaVec3 up = kern::makeVec3(0.0f, 0.0f, 1.0f);
      double mixture = 0, diffuse = 0, specular = 0;
      for (int i = 0; i < nt; ++i) {
        const double t = (i + 0.5) / nt, d = 2 * std::pow(t, 4), dd = 8 * std::pow(t, 3) / nt;
        for (int j = 0; j < nphi; ++j) {
          const kern::MaVec3 wi = kern::directionAboutD(kern::frameAbout(mirror), float(d), float((j + 0.5) / nphi));
          const float lobe = kern::phongLobe(b, wi, mirror);
          const double weight = dd * 2 * kPi / nphi;
          mixture += kern::brdfPdf(b, up, wi, lobe) * weight;
          diffuse += kern::diffusePdf(up, wi) * weight;
          specular += kern::specularPdf(b, lobe) * weight;
        }
      }
      INFO(fmt::format("view {} n {}: brdf {} diffuse {} specular {}", view, n, mixture, diffuse, specular));
      CHECK(std::abs(mixture - 1) < 1e-5);
      CHECK(std::abs(diffuse - 1) < 1e-5);
      CHECK(std::abs(specular - 1) < 1e-5);
    }
  // The envmap pdfs with zero texels: the compensated pdf draws no texel at or below
  // 2(1 − C) L̄ ([Kar19] eq. 14). (The plain pdf on every test map and the optimal pdf's
  // bank: tests/test_envmap.cpp.)
  for (const char* pdf : {"plain", "compensated"}) {
    const Scene scene = smallScene("rooitou_park", "seed000", 4, 4, false, EnvmapSampler::Alias, 0, pdf);
    if (std::string(pdf) == "compensated") REQUIRE(scene.tables.zeroTexelFraction > 0.5);
    kern::EnvmapView view = makeEnvmapView(scene.tables, -1);
    const int nu = 2 * scene.tables.width, nv = 2 * scene.tables.height;
    double integral = 0;
    for (int j = 0; j < nv; ++j) {
      const double v = (j + 0.5) / nv, rowWeight = 2 * kPi * kPi * std::sin(kPi * v) / (double(nu) * nv);
      for (int i = 0; i < nu; ++i)
        integral += kern::envmapLookup(view, kern::latLongDirection(float((i + 0.5) / nu), float(v))).pdf * rowWeight;
    }
    INFO(pdf);
    CHECK(std::abs(integral - 1) < 1e-5);
  }
}

TEST_CASE("the optimal weights' sums recover a where f is a combination of the pdfs", "[weights]") {
  // f_c = Σ_k a_ck p_k makes the residual 0 and b̃ = Ã a exactly: the kernels' sums
  // (kernels/stats.h), decoded and solved, give a back.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int M : {2, 3}) {
    const std::vector<int> n = M == 2 ? std::vector<int>{3, 5} : std::vector<int>{2, 3, 4};
    const kern::StageCounts c = countsOf(n);
    kern::OptimalCoefficients truth{};
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 0; k < M; ++k) truth.a[ch][k] = 0.5f + ch - 0.7f * k;
    SyntheticSums sums(M);
    for (int i = 0; i < 1000; ++i) {
      // Pdfs of distinct shapes along a 1D parameter x: 4(1 − x)³, 4x³ and 30 x²(1 − x)²,
      // densities on [0, 1].
      const float x = (i + 0.5f) / 1000, y = 1 - x;
      float p[MA_MAX_TECHNIQUES] = {4 * y * y * y, 4 * x * x * x, M > 2 ? 30 * x * x * y * y : 0.0f}, f[3];
      for (int ch = 0; ch < 3; ++ch) {
        f[ch] = 0;
        for (int k = 0; k < M; ++k) f[ch] += truth.a[ch][k] * p[k];
      }
      sums.add(sampleAt(i % M, p, f, c));
    }
    PixelCoefficients solved = solveOptimalWeights(sums.system());
    REQUIRE(solved.fallback == kWeightsSolved);
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 0; k < M; ++k) CHECK(solved.a[size_t(ch) * M + k] == Approx(truth.a[ch][k]).margin(1e-4));
  }
}

TEST_CASE("the system retargeted to another stage's fractions recovers a where f is a combination of the pdfs",
          "[weights]") {
  // Samples drawn with the fractions (0.5, 0.5), the weights wanted for (0.9, 0.1): each
  // sample weighted by 1/(p_β q) (RetargetedSums). Where f_c = χ_c Σ_k a_k p_k, every
  // weighting gives b̃ = Ã a, and the channels' shares are the χ_c at any fractions.
  const kern::StageCounts drawnCounts = countsOf({4, 4});
  const float chroma[3] = {0.5f, 1.0f, 2.0f}, a[2] = {0.8f, -0.3f};
  SyntheticSums drawn(2);
  RetargetedSums retargeted({0.9, 0.1});
  for (int i = 0; i < 1000; ++i) {
    const float x = (i + 0.5f) / 1000, y = 1 - x;
    float p[MA_MAX_TECHNIQUES] = {4 * y * y * y, 4 * x * x * x, 0}, f[3];
    const float ap = a[0] * p[0] + a[1] * p[1];
    for (int ch = 0; ch < 3; ++ch) f[ch] = chroma[ch] * ap;
    drawn.add(sampleAt(i % 2, p, f, drawnCounts));
    const double pdfs[2] = {p[0], p[1]};
    retargeted.add(pdfs, luminance(f[0], f[1], f[2]), 0.5 * (p[0] + p[1]));
  }
  PixelCoefficients solved = solveOptimalWeights(retargeted.system(drawn.system()));
  REQUIRE(solved.fallback == kWeightsSolved);
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 0; k < 2; ++k) CHECK(solved.a[size_t(ch) * 2 + k] == Approx(chroma[ch] * a[k]).margin(1e-4));
}

TEST_CASE("an ill-conditioned or undersampled system falls back to the balance heuristic", "[weights]") {
  // Two techniques with the same pdf: Ã is singular.
  SyntheticSums twins(2);
  const kern::StageCounts c = countsOf({4, 4});
  for (int i = 0; i < 200; ++i) {
    const float x = (i + 0.5f) / 200, p[MA_MAX_TECHNIQUES] = {2 * x, 2 * x, 0}, f[3] = {x, x, x};
    twins.add(sampleAt(i % 2, p, f, c));
  }
  PixelCoefficients singular = solveOptimalWeights(twins.system());
  CHECK(singular.fallback == kWeightsIllConditioned);
  CHECK(singular.a == std::vector<double>(6, 0.0));

  // The bound: S's least eigenvalue against its sampling noise M/√m (solveOptimalWeights).
  const double m = 400, noise = trustedEigenvalue(m, 2);
  CHECK(noise == Approx(0.1));
  for (double factor : {0.9, 1.1}) {
    const double rho = 1 - factor * noise;  // S = [[1, ρ], [ρ, 1]]: least eigenvalue 1 − ρ
    OptimalWeightsSystem s{m, Eigen::MatrixXd(2, 2), Eigen::MatrixXd::Ones(2, 3)};
    s.A << 4, 2 * rho, 2 * rho, 1;  // scales 2 and 1: the equilibration takes them out
    CHECK(solveOptimalWeights(s).fallback == (factor < 1 ? kWeightsIllConditioned : kWeightsSolved));
  }
  OptimalWeightsSystem few{kMinSamplesPerTechnique * 2 - 1, Eigen::MatrixXd::Identity(2, 2),
                           Eigen::MatrixXd::Ones(2, 3)};
  CHECK(solveOptimalWeights(few).fallback == kWeightsTooFewSamples);
  OptimalWeightsSystem nan{100, Eigen::MatrixXd::Identity(2, 2), Eigen::MatrixXd::Ones(2, 3)};
  nan.b(1, 2) = std::nan("");
  CHECK(solveOptimalWeights(nan).fallback == kWeightsNonFinite);
}

TEST_CASE("a render's pixels whose systems are ill-conditioned keep the balance heuristic and are counted",
          "[weights]") {
  // A cosine-weighted map under a diffuse-heavy lobe: the envmap's pdf ∝ cos θ is nearly
  // the BRDF's, and a pilot pooled over 25 pixels cannot tell them apart.
  const Scene collinear = smallScene("cosk:1", "uniform:0.9,0.1,20", 16, 16);
  const Rendering r = renderOptimal(collinear, Method::Equal, 64, 5);
  CHECK(r.weightsFallbacks.pixels == size_t(collinear.pixelCount()));
  CHECK(r.weightsFallbacks.illConditioned == size_t(collinear.pixelCount()));
  const AdaptiveOptions options = optimalOptions(2);
  const nlohmann::json report =
      renderReport({collinear, Method::Equal, Estimator::MultiSample, options, 64, 5, "test", r, std::nullopt});
  CHECK(report["weights"]["rule"] == "optimal");
  CHECK(report["weights"]["fallback_pixel_fraction"] == 1.0);
  CHECK(report["weights"]["fallback_reasons"]["ill_conditioned"] == collinear.pixelCount());
  // A sharp lobe is no combination of them: every pixel solves.
  const Scene distinct = smallScene("cosk:1", "uniform:0.2,0.8,50", 16, 16);
  CHECK(renderOptimal(distinct, Method::Equal, 64, 5).weightsFallbacks.pixels == 0);
}

TEST_CASE("the optimal weights change a render: another image, of lower variance than the balance heuristic's",
          "[weights]") {
  // A sharp lobe under cos θ, where every pixel solves its system (the test above): the
  // plane's pixels all integrate to eq. 6.17's value, so the mean squared error over
  // the pixels estimates each render's variance per pixel. A wiring that dropped the
  // solved weights would give the balance image bit for bit.
  const Scene scene = smallScene("cosk:1", "uniform:0.2,0.8,50", 32, 32);
  const double expected = closedForm(0.2, 0.8, 50, 1);
  auto mse = [&](const Rendering& r) {
    double sum = 0;
    for (float v : r.image.rgb) sum += (v - expected) * (v - expected);
    return sum / double(r.image.rgb.size());
  };
  const Rendering balance = renderOptimal(scene, Method::Equal, 64, 7, MisWeights::Balance);
  const Rendering optimal = renderOptimal(scene, Method::Equal, 64, 7);
  REQUIRE(optimal.weightsFallbacks.pixels == 0);
  size_t differing = 0;
  for (size_t i = 0; i < balance.image.rgb.size(); ++i) differing += balance.image.rgb[i] != optimal.image.rgb[i];
  CHECK(differing > balance.image.rgb.size() / 2);
  INFO(fmt::format("MSE balance {} optimal {}", mse(balance), mse(optimal)));
  CHECK(mse(optimal) < 0.5 * mse(balance));  // 15 times lower with seed 7
}

TEST_CASE("renders with optimal weights are unbiased against [HS14] eq. 6.17", "[weights][unbiased]") {
  // Given the stages before it, a stage's estimate is unbiased for any fixed a, and
  // the stages after the pilot are independent across pixels: the pixel mean's standard
  // error is that of independent pixels (as tests/test_adaptive.cpp argues).
  struct Case {
    double rhoD, n, K;
  };
  const std::vector<Case> cases =
      smallTestSize() ? std::vector<Case>{{0.2, 50, 1}} : std::vector<Case>{{0.2, 50, 1}, {0.05, 100, 3}};
  uint64_t seed = 900;
  BiasFamily family(0.02);
  for (const Case& c : cases) {
    const double expected = closedForm(c.rhoD, 1 - c.rhoD, c.n, c.K);
    for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf})
      for (const char* pdf : {"plain", "compensated", "optimal"}) {
        const Scene scene =
            smallScene(fmt::format("cosk:{}", c.K), fmt::format("uniform:{},{},{}", c.rhoD, 1 - c.rhoD, c.n), 32, 32,
                       false, sampler, 0, pdf);
        for (Method m : {Method::Equal, Method::Exact}) {
          Rendering r;  // the tested render, for its fallbacks
          addSized(family,
                   fmt::format("rhoD {} n {} K {} cdf {} pdf {} {}", c.rhoD, c.n, c.K, sampler == EnvmapSampler::Cdf,
                               pdf, methodName(m)),
                   expected, 64, 64, ++seed, [&](int spp, uint64_t sd) {
                     r = renderOptimal(scene, m, spp, sd);
                     return pixelMean(std::vector<double>(r.image.rgb.begin(), r.image.rgb.end()));
                   });
          INFO(fmt::format("fallbacks {}, to another table {}", r.weightsFallbacks.pixels,
                           r.weightsFallbacks.otherEnvmapTable));
          // The weights were used, but where exact's α takes the stage to another table
          // of the optimal pdf's bank (most pixels of these sharp lobes).
          CHECK(r.weightsFallbacks.pixels - r.weightsFallbacks.otherEnvmapTable < size_t(scene.pixelCount()) / 2);
          if (std::string(pdf) != "optimal") CHECK(r.weightsFallbacks.otherEnvmapTable == 0);
          if (std::string(pdf) == "optimal" && m == Method::Exact) CHECK(r.weightsFallbacks.otherEnvmapTable > 0);
        }
      }
  }
  checkFamily(family);
}

TEST_CASE("the optimal weights are refused where no multi-sample balance heuristic runs", "[weights][cli]") {
  const SceneOptions scene;
  AdaptiveOptions options = optimalOptions(2);
  for (Method m : {Method::Envmap, Method::Brdf, Method::SigmaSqrtC})
    CHECK_THROWS_WITH(requireValidRun(scene, m, Estimator::MultiSample, 64, options),
                      Catch::Contains("--weights optimal with --method " + methodName(m)));
  CHECK_THROWS_WITH(requireValidRun(scene, Method::Equal, Estimator::OneSample, 64, options),
                    Catch::Contains("--estimator one"));
  for (Method m : {Method::Equal, Method::Heuristic, Method::Linear, Method::Exact, Method::Oracle})
    CHECK_NOTHROW(requireValidRun(scene, m, Estimator::MultiSample, 64, options));
  // The entropy rule's Λ_j are the balance heuristic's.
  options.gridRule = GridRule::MaxEntropy;
  options.poolRadius = 0;
  CHECK_THROWS_WITH(requireValidRun(scene, Method::Exact, Estimator::MultiSample, 64, options),
                    Catch::Contains("--grid-rule entropy"));
  options.gridRule = GridRule::MinCostVariance;
  options.poolRadius = 2;
  // A stage too small for a sample of each technique.
  options.stages = 8;
  CHECK_THROWS_WITH(requireValidRun(scene, Method::Exact, Estimator::MultiSample, 16, options),
                    Catch::Contains("--weights optimal: a stage of 1 sample(s)"));
  TempDir dir("weights");
  const std::string out = (dir.path / "x.exr").string();
  CommandResult r = runMisalloc(
      fmt::format("render --size 4x4 --spp 16 --reference none --method sigma-sqrt-c --weights optimal --out {}", out));
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.output, Catch::Contains("count-independent weights"));
  r = runMisalloc(fmt::format("render --size 4x4 --spp 16 --reference none --weights best --out {}", out));
  CHECK(r.exitCode == 2);
  CHECK_THAT(r.output, Catch::Contains("--weights 'best'"));
  CHECK_FALSE(std::filesystem::exists(out));
}

TEST_CASE("on the papers' 1D examples the optimal weights' variance is their estimator's, never the balance's more",
          "[weights][paper]") {
  // V_opt = ∫ f²/p_α − b̃ᵀÃ⁻¹b̃ from the linear system (paper/OptimalWeightsVariance.h)
  // against the estimator's variance integrated term by term with the solved a,
  // Σ_k α_k (∫ p_k r² − (∫ p_k r)²), r = (f − a·p)/p_α, and its mean Σ_k a_k + ∫ (f − a·p)
  // against I. Both integrals by adaptive quadrature; cancellation is measured against
  // ∫ f²/p_α, which V_opt may undercut by orders of magnitude.
  int compared = 0;
  for (const std::string& id : paperExampleIds()) {
    const Example1D example = paperExample(id);
    const int m = example.techniqueCount();
    std::vector<std::vector<double>> alphas{std::vector<double>(m, 1.0 / m)};
    for (int k = 0; k < m; ++k) {
      std::vector<double> skewed(m, 0.3 / (m - 1));
      skewed[k] = 0.7;
      alphas.push_back(skewed);
    }
    for (const std::vector<double>& alpha : alphas) {
      const OptimalWeightsSolution optimal = optimalWeightsVariance(example, alpha);
      if (optimal.variance.status != VarianceStatus::Finite) continue;  // 000-C's signed "density"
      const std::vector<double>& a = optimal.a;
      const int components = 2 * m + 1;
      auto terms = [&](double x, double* out) {
        std::fill(out, out + components, 0.0);
        const double p = example.mixturePdf(alpha, x);
        if (!(p > 0)) return;
        double ap = 0;
        for (int k = 0; k < m; ++k) ap += a[k] * example.pdf(k)(x);
        const double r = (example.f(x) - ap) / p;
        for (int k = 0; k < m; ++k) {
          out[2 * k] = example.pdf(k)(x) * r * r;
          out[2 * k + 1] = example.pdf(k)(x) * r;
        }
        out[2 * m] = example.f(x) * example.f(x) / p;
      };
      const QuadratureResult q = integrateAdaptive(terms, components, example.lower(), example.upper());
      double direct = 0, mean = 0, sumA = 0;
      for (int k = 0; k < m; ++k) {
        direct += alpha[k] * (q.value[2 * k] - q.value[2 * k + 1] * q.value[2 * k + 1]);
        mean += alpha[k] * q.value[2 * k + 1];  // ∫ p_α r = ∫ (f − a·p)
        sumA += a[k];
      }
      const double scale = q.value[2 * m];
      // Where f is a combination of the pdfs (002-3), r is rounding noise that no
      // relative tolerance resolves; its integrals are then that small.
      CHECK((q.converged || std::abs(direct) <= 1e-12 * scale));
      const double balance = multiSampleVariance(example, alpha).value;
      INFO(fmt::format("{} alpha ({}): V_opt {} direct {} balance {}", id, fmt::join(alpha, ", "),
                       optimal.variance.value, direct, balance));
      CHECK(std::abs(optimal.variance.value - direct) <= 1e-8 * scale);
      CHECK(sumA + mean == Approx(example.integral()).epsilon(1e-9));
      CHECK(optimal.variance.value <= balance + 1e-10 * scale);
      ++compared;
    }
  }
  CHECK(compared >= 40);
}

TEST_CASE("compare runs each scene with each weights and compares them at the same counts", "[weights][compare][cli]") {
  TempDir dir("compare_weights");
  const std::filesystem::path out = dir.path / "out";
  CommandResult r = runMisalloc(fmt::format(
      "compare --envmap cosk:1 --grid uniform:0.2,0.8,50 --size 8x8 --budgets 20,40 --repeats 1 --envmap-pdfs plain "
      "--methods equal,exact,sigma-sqrt-c --weights balance,optimal --device cpu --out-dir {} --cache-dir {}",
      out.string(), (dir.path / "cache").string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  const nlohmann::json runs = nlohmann::json::parse(std::ifstream(out / "runs.json"));
  REQUIRE(runs["cases"].size() == 2);
  CHECK(runs["cases"][0]["label"] == "cosk_1");
  CHECK(runs["cases"][0]["weights"] == "balance");
  CHECK(runs["cases"][1]["label"] == "cosk_1-optimal-weights");
  CHECK(runs["cases"][1]["weights"] == "optimal");
  // σ/√c allocates for its count-independent weights: left out of the optimal case alone.
  REQUIRE(runs["cases"][1]["left_out"].size() == 1);
  CHECK(runs["cases"][1]["left_out"][0]["method"] == "sigma-sqrt-c");
  CHECK(runs["runs"].size() == (3 + 2) * 2);
  std::ifstream weights(out / "weights.md");
  const std::string tables((std::istreambuf_iterator<char>(weights)), std::istreambuf_iterator<char>());
  CHECK_THAT(tables, Catch::Contains("Optimal weights ([Kon19]) against the balance heuristic, 40 spp"));
  CHECK_THAT(tables, Catch::Contains("| exact | plain |"));
  CHECK(std::filesystem::exists(out / "cosk_1-optimal-weights" / "equal_40spp.exr"));
  for (const char* bad : {"--weights balance,balance", "--weights best"}) {
    CommandResult refused = runMisalloc(fmt::format("compare --envmap cosk:1 --size 8x8 --budgets 20 {} --out-dir {}",
                                                    bad, (dir.path / "refused").string()));
    CHECK(refused.exitCode == 2);
    CHECK_FALSE(std::filesystem::exists(dir.path / "refused"));
  }
}
