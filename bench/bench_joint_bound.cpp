// How much choosing the optimal pdf's table jointly with α could gain over the rule
// that runs today, where a stage samples with the entry whose share C is nearest its
// own α_0 (bankEntryOf, kernels/envmap.h). An oracle bound: for every pixel, two
// independent equal-count probes (envmap samples with the C = 1/2 entry, BRDF samples);
// each rule picks its (α, table) by least cost × multi-sample variance ([SHS16] eq. 21)
// on the first probe, and the pick is judged on the second, so that the noise the pick
// was fitted to does not flatter it. Per image, at equal time, a rule's error is
// ∝ (Σ_pixels c·α) · (Σ_pixels V): the bound is that product's ratio between the rules.
//
//   build/bench/misalloc_bench_joint_bound [--envmap M]... [--size 128x128]
//       [--probe-spp 512] [--grid-u 80] [--cost 1,1]
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <array>
#include <cmath>
#include <cstdio>
#include <vector>

#include "KernelCode.h"
#include "sampling/CostModel.h"
#include "sampling/KernelViews.h"
#include "scene/Scene.h"

using namespace misalloc;

namespace {

// One probe sample: f's luminance over the probe's mixture pdf q, and the pdfs every
// candidate needs: BRDF sampling's and the envmap's under each of the bin's entries.
struct ProbeSample {
  double yOverQ, y;
  float brdfPdf;
  std::vector<float> envmapPdfs;  // per share
};

// What the choice of (α_0, share) costs and gives on one probe: cost × variance terms.
class ProbeVariance {
 public:
  ProbeVariance(std::vector<ProbeSample> samples) : samples_(std::move(samples)) {}

  // [SHS16] eq. 21 with the probe's estimates: V(α) = ∫ f²/p_α − Σ_j α_j μ_j², μ_j =
  // ∫ f p_j / p_α, every integral estimated as the mean of h/q over the probe.
  double variance(double alpha0, int share) const {
    double second = 0, mu0 = 0, mu1 = 0;
    for (const ProbeSample& s : samples_) {
      double p0 = s.envmapPdfs[share], p1 = s.brdfPdf;
      double pAlpha = alpha0 * p0 + (1 - alpha0) * p1;
      if (pAlpha <= 0) continue;  // q > 0 but no candidate covers it: f = 0 there
      double w = s.yOverQ / pAlpha;
      second += w * s.y;
      mu0 += w * p0;
      mu1 += w * p1;
    }
    double n = double(samples_.size());
    second /= n, mu0 /= n, mu1 /= n;
    return second - alpha0 * mu0 * mu0 - (1 - alpha0) * mu1 * mu1;
  }

 private:
  std::vector<ProbeSample> samples_;
};

struct Pick {
  double alpha0 = 0.5;
  int share = 0;
};

// The share bankEntryOf takes for α_0, from the kernel's own function.
int nearestShare(const kern::EnvmapView& env, double alpha0) {
  kern::EnvmapView e = env;
  e.brdfBin = 0;
  return kern::bankEntryOf(e, float(alpha0));
}

// Which shares a rule weighs α_0 with when it selects, and which share the stage then
// runs with.
enum class Rule {
  Nearest,     // selects with the share it runs, the one nearest α_0
  Joint,       // selects among every share, runs the one it selected
  Mismatched,  // selects as if the probe's share (C = 1/2) ran, runs the one nearest α_0: exact today
  Half,        // selects and runs with C = 1/2 whatever α_0
};

int runShare(Rule rule, const kern::EnvmapView& env, double alpha0, int selected) {
  if (rule == Rule::Joint) return selected;
  return rule == Rule::Half ? nearestShare(env, 0.5) : nearestShare(env, alpha0);
}

// The (α_0, share) the stage runs with: the α_0 with least (c_0 α_0 + c_1 α_1) · V on
// `probe`, as the rule weighs it.
Pick bestPick(const ProbeVariance& probe, const kern::EnvmapView& env, int gridU, const std::array<double, 2>& c,
              Rule rule) {
  Pick best;
  double bestScore = INFINITY;
  for (int l = 0; l < gridU; ++l) {
    double alpha0 = (l + 0.5) / gridU;
    for (int share = 0; share < env.bankShares; ++share) {
      const int weighed = rule == Rule::Nearest ? nearestShare(env, alpha0)
                          : rule == Rule::Joint ? share
                                                : nearestShare(env, 0.5);
      if (share != weighed) continue;
      double score = (c[0] * alpha0 + c[1] * (1 - alpha0)) * probe.variance(alpha0, share);
      if (score < bestScore) bestScore = score, best = {alpha0, runShare(rule, env, alpha0, share)};
    }
  }
  return best;
}

// An equal-count probe of `spp` samples of one pixel; `stream` keeps the probes apart.
std::vector<ProbeSample> probePixel(const Scene& scene, kern::EnvmapView env, int pixel, int spp, uint32_t stream) {
  kern::TechniqueSet ts;
  ts.techniqueCount = 2;
  ts.splitBrdf = 0;
  ts.product.tables = ts.product.pixelCells = 0;
  const kern::ShadingPoint sp = makeShadingPoint(scene, pixel);
  env.brdfBin = scene.tables.brdfBinOfPixel[pixel];
  const int probeShare = nearestShare(env, 0.5);
  std::vector<ProbeSample> samples;
  for (int i = 0; i < spp; ++i) {
    int technique = i % 2;
    env.bankEntry = env.brdfBin * env.bankShares + probeShare;
    kern::MaRandom4 rnd = kern::philoxDraw(stream, 0x6a6f696eu, uint32_t(pixel), uint32_t(technique), uint32_t(i));
    kern::TechniqueSample t = kern::sampleTechnique(ts, env, sp, technique, rnd, 0.0f);
    kern::SampleValue v = kern::evaluateSample(ts, env, sp, technique, t);
    int texel = technique == 0 ? t.texel : kern::texelOfDirection(env, t.wi);
    float sinTheta = std::sqrt(t.wi.x * t.wi.x + t.wi.y * t.wi.y);
    ProbeSample s;
    s.y = kern::luminance(v.r, v.g, v.b);
    s.brdfPdf = v.pdfs[1];
    for (int share = 0; share < env.bankShares; ++share) {
      env.bankEntry = env.brdfBin * env.bankShares + share;
      s.envmapPdfs.push_back(kern::envmapPdfOfTexel(env, kern::texelProbability(env, texel), sinTheta));
    }
    double q = 0.5 * s.envmapPdfs[probeShare] + 0.5 * s.brdfPdf;
    s.yOverQ = q > 0 ? s.y / q : 0;
    samples.push_back(std::move(s));
  }
  return samples;
}

struct RuleTotals {
  double cost = 0, variance = 0;
  double equalTime() const { return cost * variance; }
};

void measure(const std::string& map, int width, int height, int spp, int gridU, const std::array<double, 2>& c) {
  SceneOptions o;
  o.envmap = map;
  o.width = width, o.height = height;
  o.envmapPdf = parseEnvmapPdf("optimal");
  const Scene scene = makeScene(o);
  if (!scene.tables.hasBank()) throw std::runtime_error(map + ": the optimal pdf fell back to plain tables");
  const kern::EnvmapView env = makeEnvmapView(scene.tables, scene.envmap.coskExponent);
  const std::array<Rule, 4> rules{Rule::Nearest, Rule::Joint, Rule::Mismatched, Rule::Half};
  std::array<RuleTotals, 4> totals;
  RuleTotals equal;
  int changedShare = 0;
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : changedShare)
  for (int pixel = 0; pixel < scene.pixelCount(); ++pixel) {
    ProbeVariance fit(probePixel(scene, env, pixel, spp, 1)), judge(probePixel(scene, env, pixel, spp, 2));
    std::array<Pick, 5> picks;
    for (size_t r = 0; r < rules.size(); ++r) picks[r] = bestPick(fit, env, gridU, c, rules[r]);
    picks[4] = {0.5, nearestShare(env, 0.5)};
    changedShare += picks[1].share != nearestShare(env, picks[1].alpha0);
#pragma omp critical
    for (size_t r = 0; r < picks.size(); ++r) {
      RuleTotals& t = r < rules.size() ? totals[r] : equal;
      t.cost += c[0] * picks[r].alpha0 + c[1] * (1 - picks[r].alpha0);
      t.variance += judge.variance(picks[r].alpha0, picks[r].share);
    }
  }
  const RuleTotals& nearest = totals[0];
  fmt::print("| {} | {:.3f}x | {:.3f}x | {:.3f}x | {:.3f}x | {:.3f}x | {:.1f} % |\n", map,
             equal.equalTime() / totals[3].equalTime(), equal.equalTime() / totals[2].equalTime(),
             equal.equalTime() / nearest.equalTime(), equal.equalTime() / totals[1].equalTime(),
             nearest.equalTime() / totals[1].equalTime(), 100.0 * changedShare / scene.pixelCount());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app("The bound on choosing the optimal pdf's table jointly with alpha");
  std::vector<std::string> maps;
  std::string size = "128x128", costs = "1,1";
  int spp = 512, gridU = 80;
  app.add_option("--envmap", maps, "maps (default: the shipped ones and two procedural suns)");
  app.add_option("--size", size, "WxH pixels");
  app.add_option("--probe-spp", spp, "samples of each of the two probes per pixel")->check(CLI::Range(2, 1 << 20));
  app.add_option("--grid-u", gridU, "alpha_0 grid, (l + 1/2)/U")->check(CLI::Range(1, 4096));
  app.add_option("--cost", costs, "cost per sample of envmap and BRDF sampling");
  CLI11_PARSE(app, argc, argv);
  if (maps.empty()) {
    maps = shippedEnvmapNames();
    maps.insert(maps.end(), {"sun:40,90,0.5,1e5", "sun:20,0,3,300"});
  }
  int width = 0, height = 0;
  if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2 || width < 1 || height < 1) {
    fmt::print(stderr, "--size: WxH, got {}\n", size);
    return 2;
  }
  std::vector<double> parsed = parseCosts(costs, 2);
  const std::array<double, 2> c{parsed[0], parsed[1]};
  fmt::print("{}x{}, probes of {} spp, U = {}, costs {}\n\n", width, height, spp, gridU, costs);
  fmt::print("Each rule's error at equal time, as a gain over α = 1/2 with C = 1/2 (equal):\n\n");
  fmt::print(
      "| map | C = 1/2 | mismatched (exact today) | nearest | joint | joint over nearest | pixels whose joint share is "
      "not the nearest |\n");
  fmt::print("|---|---|---|---|---|---|---|\n");
  for (const std::string& map : maps) measure(map, width, height, spp, gridU, c);
}
