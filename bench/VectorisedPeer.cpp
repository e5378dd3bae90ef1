// VectorisedPeer: kernels/sample.cl's plain multi-sample stage, vectorised by g++ across
// each technique's samples (bench/CMakeLists.txt has its flags).
#include "VectorisedPeer.h"

#include <algorithm>
#include <stdexcept>

#include "sampling/KernelViews.h"

namespace misalloc::bench {

namespace {

// One technique's sums over its samples of a pixel: what addContribution adds.
struct TechniqueSums {
  double r = 0, g = 0, b = 0, w = 0, ww = 0;
};

// What the pass of one pixel reads: the scene's views, the pixel's shading point, counts and key.
struct PixelPass {
  kern::EnvmapView env;
  kern::TechniqueSet ts;
  kern::ShadingPoint point;
  kern::StageCounts counts;
  uint32_t seedLo, seedHi, pixelKey;
};

// The CDF sampler's searches take a fixed number of steps, a constant that sample.cl
// is compiled with (MA_CDF_STEPS_ROW, MA_CDF_STEPS_COL) and unrolls; g++ vectorises no
// loop with a loop inside. The peer instantiates the searches with one count for both,
// the larger: a step past the last leaves the search where it is (its span is 1), so
// the samples are the kernel's, for at most one step more. Maps up to 2^14 texels across.
constexpr int kMaxCdfSteps = 14;

// What a sample adds to its pixel's sums: SampleContribution's r, g, b and w.
struct SampleTerm {
  float r, g, b, w;
};

// The BRDF technique's sample `index`, as takeTechniqueSample takes it, but for the
// lobe: sampleBrdf picks it with a branch around both lobes' inlined code, and g++ 12
// does not if-convert a block with an internal call in it (sinCos2Pi's truncation
// becomes .TRUNC), so that the loop would stay scalar. Both lobes are drawn here and
// one selected, the kernel's direction; the rest is takeTechniqueSample's code
// (kernels/pixel.h) for technique 1: the balance heuristic's f / (N p_α), [HS14] eq. 4.2.
SampleTerm brdfTerm(const PixelPass& p, uint32_t index) {
  const kern::MaRandom4 rnd = kern::philoxDraw(p.seedLo, p.seedHi, p.pixelKey, 1u, index);
  const float u1 = kern::uniformFloat(rnd.v[1]), u2 = kern::uniformFloat(rnd.v[2]);
  const kern::MaVec3 diffuse = kern::sampleDiffuse(p.point.normalFrame, u1, u2);
  const kern::MaVec3 specular = kern::sampleSpecular(p.point.brdf, p.point.mirrorFrame, u1, u2);
  const bool isDiffuse = kern::uniformFloat(rnd.v[0]) < kern::diffuseLobeWeight(p.point.brdf);
  kern::TechniqueSample drawn;
  drawn.wi = kern::makeVec3(isDiffuse ? diffuse.x : specular.x, isDiffuse ? diffuse.y : specular.y,
                            isDiffuse ? diffuse.z : specular.z);
  drawn.texel = 0;
  const kern::SampleValue v = kern::evaluateSample(p.ts, p.env, p.point, 1, drawn);
  float alpha[MA_MAX_TECHNIQUES];
  kern::stageFractions(p.counts, alpha);
  const float mixture = kern::mixturePdf(2, alpha, v.pdfs), N = float(p.counts.stageSamples);
  const float invP = mixture > 0.0f ? 1.0f / mixture : 0.0f;
  return {v.r * invP / N, v.g * invP / N, v.b * invP / N, kern::luminance(v.r, v.g, v.b) * invP};
}

// The n_k samples of `Technique`, with the constants sample.cl is compiled with for this
// shape set here, so that g++ folds the branches the kernel's compiler folds.
// CdfSteps 0: the alias sampler.
template <int Technique, int CdfSteps>
TechniqueSums techniquePass(PixelPass p) {
  p.env.useCdf = CdfSteps > 0;
  p.env.cdfStepsRow = p.env.cdfStepsCol = CdfSteps;
  p.env.coskExponent = -1.0f;  // the texels' radiance
  p.env.bankShares = 0;
  p.ts.techniqueCount = p.counts.techniqueCount = 2;
  p.ts.splitBrdf = p.ts.sharePdfs = p.ts.product.tables = p.ts.product.pixelCells = 0;
  p.counts.oneSample = p.counts.countIndependent = p.counts.risCandidates = 0;
  const int n = Technique == 0 ? p.counts.n0 : p.counts.n1;
  const uint32_t first = kern::firstIndexOf(p.counts, Technique);
  double r = 0, g = 0, b = 0, w = 0, ww = 0;
#pragma omp simd reduction(+ : r, g, b, w, ww)
  for (int j = 0; j < n; ++j) {
    SampleTerm s;
    if constexpr (Technique == 0) {
      const kern::SampleContribution c = kern::takeTechniqueSample(p.ts, p.env, p.point, p.counts, 0,
                                                                   first + uint32_t(j), p.seedLo, p.seedHi, p.pixelKey);
      s = {c.r, c.g, c.b, c.w};
    } else {
      s = brdfTerm(p, first + uint32_t(j));
    }
    const double sw = s.w;
    r += s.r;
    g += s.g;
    b += s.b;
    w += sw;
    ww += sw * sw;
  }
  return {r, g, b, w, ww};
}

// Adds a pixel's envmap and BRDF passes to its estimate and writes their moments.
template <int CdfSteps>
void pixelPasses(const PixelPass& p, double* rgb, double* moments) {
  // The BRDF technique reads the texels only, whichever the sampler.
  const TechniqueSums sums[2] = {techniquePass<0, CdfSteps>(p), techniquePass<1, 0>(p)};
  for (int k = 0; k < 2; ++k) {
    rgb[0] += sums[k].r;
    rgb[1] += sums[k].g;
    rgb[2] += sums[k].b;
    moments[2 * k] = sums[k].w;
    moments[2 * k + 1] = sums[k].ww;
  }
}

using PixelPasses = void (*)(const PixelPass&, double*, double*);

// The CDF sampler's passes with at least `steps` steps per search.
template <int Steps = 1>
PixelPasses cdfPasses(int steps) {
  if constexpr (Steps < kMaxCdfSteps)
    if (steps > Steps) return cdfPasses<Steps + 1>(steps);
  return &pixelPasses<Steps>;
}

}  // namespace

VectorisedPeer::VectorisedPeer(const Scene& scene) : scene_(scene) {
  if (scene.options.splitBrdf || scene.tables.hasBank() || scene.envmap.coskExponent >= 0)
    throw std::invalid_argument(
        "the vectorised peer runs two techniques with the plain pdf on a map's texels only: no --split-brdf, no "
        "optimal pdf, no cosk map");
  if (std::max(scene.tables.cdfStepsRow, scene.tables.cdfStepsCol) > kMaxCdfSteps)
    throw std::invalid_argument("the vectorised peer's CDF searches take at most 14 steps: a map too large");
}

StageResult VectorisedPeer::run(const StagePlan& plan, uint64_t seed) const {
  if (plan.techniqueCount != 2 || !plan.optimalCoefficients.empty())
    throw std::invalid_argument("the vectorised peer runs the balance heuristic of two techniques only");
  const int pixels = scene_.pixelCount();
  PixelPass shared{};
  shared.env = makeEnvmapView(scene_.tables, scene_.envmap.coskExponent);
  shared.seedLo = uint32_t(seed);
  shared.seedHi = uint32_t(seed >> 32);
  StageResult result;
  result.rgb.assign(size_t(pixels) * 3, 0.0);
  result.moments.assign(size_t(pixels) * 4, 0.0);
  const PixelPasses passes = scene_.tables.useCdf
                                 ? cdfPasses(std::max(scene_.tables.cdfStepsRow, scene_.tables.cdfStepsCol))
                                 : &pixelPasses<0>;
#pragma omp parallel for schedule(dynamic, 64)
  for (int pixel = 0; pixel < pixels; ++pixel) {
    PixelPass p = shared;
    p.point = makeShadingPoint(scene_, pixel);
    p.counts = kern::loadStageCounts(plan.counts.data(), plan.firstIndex.data(), pixel, 2, plan.stageSamples, 0, 0, 0);
    p.pixelKey = uint32_t(scene_.firstPixel + pixel);
    passes(p, result.rgb.data() + size_t(pixel) * 3, result.moments.data() + size_t(pixel) * 4);
  }
  return result;
}

}  // namespace misalloc::bench
