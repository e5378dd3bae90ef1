// HostSampler: the C++ reference of kernels/sample.cl, through host/KernelCode.h.
#include "sampling/HostSampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

#include "KernelCode.h"
#include "cl/KernelSource.h"
#include "sampling/KernelViews.h"

namespace misalloc {

kern::EnvmapView makeEnvmapView(const EnvmapTables& t, float coskExponent) {
  kern::EnvmapView env;
  env.texels = t.texels.data();
  env.cdfTable = t.cdfTable.data();
  env.aliasTable = t.aliasTable.data();
  env.width = t.width;
  env.height = t.height;
  env.useCdf = t.useCdf ? 1 : 0;
  env.cdfStepsRow = t.cdfStepsRow;
  env.cdfStepsCol = t.cdfStepsCol;
  env.coskExponent = coskExponent;
  env.bankShares = t.bankShares;
  env.blockLog2 = t.blockLog2;
  env.blockProbs = t.blockProbs.data();
  env.brdfBin = 0;
  env.bankEntry = 0;
  env.pixelCells = t.pixelCells;
  env.pixelCdf = nullptr;
  env.pixelCdfStride = 1;
  env.pixelCdfSteps = t.pixelCdfSteps;
  return env;
}

kern::ProductView makeProductView(const ProductTables& t) {
  kern::ProductView p;
  p.floats = t.floats.data();
  p.words = t.words.data();
  p.tables = t.tables;
  p.blockLog2 = t.blockLog2;
  p.plainTexels = t.plainTexels ? 1 : 0;
  p.pixelCells = t.pixelCells ? 1 : 0;
  return p;
}

kern::ShadingPoint makeShadingPoint(const Scene& scene, int pixel) {
  const PhongParameters& p = scene.grid.pixels[pixel];
  kern::ShadingPoint sp;
  sp.brdf.rhoD = p.rhoD;
  sp.brdf.rhoS = p.rhoS;
  sp.brdf.n = p.n;
  const PixelFrame& f = scene.geometry.pixels[pixel];
  sp.normalFrame = kern::frameAbout(kern::makeVec3(f.normal[0], f.normal[1], f.normal[2]));
  sp.mirrorFrame = kern::frameAbout(kern::makeVec3(f.mirror[0], f.mirror[1], f.mirror[2]));
  return sp;
}

namespace {

// Pixel p's coefficients of the optimal weights as kernels/sample.cl reads them: all 0
// where the plan has none.
kern::OptimalCoefficients optimalCoefficients(const StagePlan& plan, int pixel, int M) {
  kern::OptimalCoefficients a{};
  if (plan.optimalCoefficients.empty()) return a;
  const float* row = plan.optimalCoefficients.data() + kern::coefficientsOffset(pixel, M);
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 0; k < M; ++k) a.a[ch][k] = row[ch * M + k];
  return a;
}

kern::StageCounts stageCountsOf(const StagePlan& plan, const SamplerConfig& config, int pixel) {
  return kern::loadStageCounts(plan.counts.data(), plan.firstIndex.data(), pixel, plan.techniqueCount,
                               plan.stageSamples, config.estimator == Estimator::OneSample,
                               config.estimator == Estimator::CountIndependent, config.risCandidates);
}

kern::PixelCdfInputs cdfInputsOf(const kern::ShadingPoint& sp, const kern::StageCounts& c,
                                 const kern::TechniqueSet& ts) {
  return kern::cdfInputsOf(sp.brdf, sp.normalFrame.z, sp.mirrorFrame.z, c, kern::productEnabled(ts.product));
}

// The inputs of the table that `pixel` samples, given its own: its quad's, its pair's or
// its own (kernels/pixel_pairs.h), read in the order kernels/sample.cl's pixelTableGroup
// reads them.
kern::PixelCdfInputs tableInputs(const Scene& scene, const StagePlan& plan, const SamplerConfig& config, int pixel,
                                 const kern::PixelCdfInputs& own, const kern::TechniqueSet& ts, int cells) {
  const int width = scene.grid.width, x = pixel % width, row = pixel - x, partner = kern::pairPartner(x);
  if (partner >= width) return own;
  auto inputsOf = [&](int q, int& samples) {
    const kern::StageCounts c = stageCountsOf(plan, config, q);
    samples = kern::pixelStageSamples(c) > 0;
    return cdfInputsOf(makeShadingPoint(scene, q), c, ts);
  };
  int partnerSamples = 0, aSamples = 0, bSamples = 0;
  const kern::PixelCdfInputs p = inputsOf(row + partner, partnerSamples);
  const kern::PairTable pair = kern::pairTableOf(own, p, partnerSamples, cells);
  if (!pair.shares) return own;
  if (kern::quadPlaces(x, width) < 4) return pair.mean;
  const int other = row + kern::otherPairFirst(x);
  const kern::PixelCdfInputs a = inputsOf(other, aSamples), b = inputsOf(other + 1, bSamples);
  return kern::quadGroup(pixel, x, pair, kern::pairTableOf(a, b, aSamples && bSamples, cells), cells).inputs;
}

}  // namespace

HostSampler::HostSampler(const Scene& scene, const SamplerConfig& config)
    : StageSampler(scene, config), stats_(size_t(scene.pixelCount()) * statSlots(), 0.0) {
  share_.name = kHostSamplerName;
  if (config.sampleCapacity > 0) samples_ = emptyStoredSamples(scene, config);
}

std::string HostSampler::launchIdentity() const {
  // The C++ reference is this binary's code: the compiler and how it built it, and the
  // kernel sources it mirrors, stand for its build.
#if defined(__SANITIZE_ADDRESS__)
  constexpr const char* kBuild = "sanitized";
#elif defined(__OPTIMIZE__)
  constexpr const char* kBuild = "optimised";
#else
  constexpr const char* kBuild = "unoptimised";
#endif
  return fmt::format("host C++ reference, {} {} build; kernel sources {:016x}", __VERSION__, kBuild,
                     embeddedSourcesHash());
}

void HostSampler::forgetStages() {
  std::fill(stats_.begin(), stats_.end(), 0.0);
  share_ = share_.restarted();
}

StageResult HostSampler::runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) {
  const int M = scene_.techniqueCount();
  const SamplerConfig config = plan.keepStatistics ? config_ : plainConfig(config_);
  const EnvmapTables& tables = stageTables(scene_, keepsStatistics(config));
  kern::EnvmapView env = makeEnvmapView(tables, scene_.envmap.coskExponent);
  kern::TechniqueSet ts;
  ts.techniqueCount = M;
  ts.splitBrdf = scene_.options.splitBrdf ? 1 : 0;
  ts.product = makeProductView(scene_.productTables);
  ts.productMixture = {};
  const SampleColumns columns = sampleColumns(scene_, config);
  ts.sharePdfs = columns.shareColumns > 0 ? 1 : 0;
  const int slots = plan.keepStatistics ? statSlots() : 0;
  const int perTechnique = MA_STATS_PER_TECHNIQUE(int(config.statsMask), M);
  StageResult result;
  result.rgb.assign(kern::estimateOffset(range.size()), 0.0);
  result.moments.assign(kern::momentsOffset(range.size(), M), 0.0);
  auto start = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(dynamic, 64)
  for (int pixel = range.begin; pixel < range.end; ++pixel) {
    kern::EnvmapView pixelEnv = env;
    if (scene_.tables.hasBank()) pixelEnv.brdfBin = scene_.tables.brdfBinOfPixel[pixel];
    const kern::ShadingPoint sp = makeShadingPoint(scene_, pixel);
    kern::TechniqueSet pixelTs = ts;
    if (ts.product.tables > 0) pixelTs.productMixture = kern::productMixture(ts.product, sp.brdf);
    const kern::StageCounts c = stageCountsOf(plan, config_, pixel);
    const kern::OptimalCoefficients a = optimalCoefficients(plan, pixel, M);
    std::vector<int> pixelCdf(MA_PIXEL_CDF_ROWS(env.pixelCells, ts.product.pixelCells, ts.sharePdfs));
    if (env.pixelCells > 0 && kern::pixelStageSamples(c) > 0) {
      const kern::PixelCdfInputs in =
          tableInputs(scene_, plan, config_, pixel, cdfInputsOf(sp, c, ts), ts, env.pixelCells);
      kern::buildPixelOptimalCdf(tables.blockProbs.data(), env.pixelCells, in.brdf, in.normal, in.mirror,
                                 in.envmapShare, in.brdfCovers, ts.sharePdfs, ts.product.pixelCells, pixelCdf.data(),
                                 1);
      pixelEnv.pixelCdf = pixelCdf.data();
    }
    kern::PixelSums sums = kern::zeroPixelSums();
    double* running = stats_.data() + kern::statsOffset(pixel, slots);
    for (int j = 0; j < kern::pixelStageSamples(c); ++j) {
      kern::SampleContribution s = kern::takeStageSample(pixelTs, pixelEnv, sp, c, j, uint32_t(seed),
                                                         uint32_t(seed >> 32), uint32_t(scene_.firstPixel + pixel));
      if (config_.optimalWeights) s = kern::withOptimalWeights(s, c, a);
      kern::addContribution(&sums, s);
      for (int slot = 0; slot < slots; ++slot)
        if (s.technique == slot / perTechnique)
          running[slot] += kern::statValue(int(config.statsMask), M, slot % perTechnique, s);
      if (config.sampleCapacity > 0) {
        int i = firstSlot + j;
        const int C = columns.count();
        samples_[kern::storedSampleIndex(pixel, i, 0, config_.sampleCapacity, C)] =
            float(kern::storedColumn(s, columns.shareColumns));
        samples_[kern::storedSampleIndex(pixel, i, 1, config_.sampleCapacity, C)] =
            kern::storedSampleValue(int(config.statsMask), s);
        for (int l = 0; l < C; ++l)
          samples_[kern::storedSampleIndex(pixel, i, 2 + l, config_.sampleCapacity, C)] =
              kern::storedPdf(s, columns.shareColumns, l);
      }
    }
    const int row = pixel - range.begin;
    double* rgb = result.rgb.data() + kern::estimateOffset(row);
    rgb[0] = sums.r;
    rgb[1] = sums.g;
    rgb[2] = sums.b;
    const double moments[6] = {sums.w0, sums.ww0, sums.w1, sums.ww1, sums.w2, sums.ww2};
    std::copy(moments, moments + 2 * M, result.moments.data() + kern::momentsOffset(row, M));
  }
  result.kernelSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  share_.pixelStages += range.size();
  share_.samples += (long long)range.size() * plan.stageSamples;
  share_.tiles += 1;
  share_.kernelSeconds += result.kernelSeconds;
  return result;
}

}  // namespace misalloc
