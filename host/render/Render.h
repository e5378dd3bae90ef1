#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "alloc/GridSearch.h"
#include "alloc/LinearAllocation.h"
#include "alloc/OptimalWeights.h"
#include "render/Method.h"
#include "render/MisWeights.h"
#include "sampling/Sampler.h"
#include "scene/ExrIO.h"

namespace misalloc {

// The candidates of a `ris` sample unless --ris-candidates says otherwise: of 1, 2, 4, 8
// and 16, the best at equal time against `equal` on three maps (docs/results.md, "RIS as
// a baseline"). Each candidate costs a whole evaluation of f, so more buy little.
inline constexpr int kDefaultRisCandidates = 2;
// The kernel unrolls its candidate loop, one copy of envmap sampling per candidate
// (kernels/ris.h). At 32, LLVM 15 leaves it rolled and PoCL's sample loop scalar: 3× the
// time per candidate of 16 (docs/results.md).
inline constexpr int kMaxRisCandidates = 16;

// exact's whole-image rule keeps equal counts where its predicted gain is below this
// (--skip-image-below): where the pilot predicts that the allocation loses at equal
// time. A margin above 1 gave up more real gains than it saved losses (docs/results.md,
// "The whole-image rule").
inline constexpr double kDefaultImageGainBelow = 1.0;

// The batched schedule of the adaptive methods ([HS14] Algorithm 1, Sec. 5.2), and the
// options of the other methods that take any (oracle, ris).
struct AdaptiveOptions {
  double pilotFraction = 0.05;  // of N, split equally among the techniques (pilotSamples)
  int stages = 1;               // after the pilot
  int poolRadius = 2;           // statistics pooled over (2r + 1)² pixels (alloc/Pooling.h)
  double minGain = 0.02;        // exact: the skip rule's least predicted gain (alloc/GridSearch.h, PooledSelection)
  // exact: the whole-image rule's least predicted gain at equal time (alloc/WholeImageRule.h)
  double imageGainBelow = kDefaultImageGainBelow;
  std::vector<double> costs;  // c_k per sample, one per technique (--cost); empty: the sampler's CostModel
  bool measureCosts = false;  // --cost measure: the caller calibrates the samplers again (render/CostCache.h)
  ZeroWeightRule linearRule = ZeroWeightRule::MinSampleVariance;
  int gridSize = kDefaultGridSize;  // exact: U weight combinations
  GridRule gridRule = GridRule::MinCostVariance;
  int oracleSamples = 1024;                   // oracle: equal-count probe samples per pixel
  int risCandidates = kDefaultRisCandidates;  // ris: envmap candidates per sample ([TCE05])
  // The weights of every stage after the first: with Optimal, equal also runs a pilot
  // (render/Render.cpp, docs/methods.md).
  MisWeights weights = MisWeights::Balance;
};

// The pilot of exact, and of equal with optimal weights, takes at least this many
// samples per technique, where that costs at most an eighth of the budget
// (pilotSamples). exact's grid search ranks α from the pilot's samples pooled over a
// window; 5 per technique (a 5 % pilot at 200 spp) misjudged small suns, 8 did not. A
// larger pilot costs image quality: its samples come from the coarser pilot table
// (Scene::pilotTables), and the search reads every one (docs/results.md, "A smaller
// pilot").
inline constexpr int kPilotSamplesPerTechnique = 8;

// The pilot of a method whose α is a per-pixel rule over running sums (heuristic,
// sigma-sqrt-c, linear) fills whole passes of this many samples per technique where
// that keeps it within a quarter of the budget (pilotSamples): heuristic's and linear's
// variance ratios, from 8 samples per technique, misjudged α (docs/results.md, "The
// pilot's size by method"). 16 was AVX-512's lanes in samplePixelStage when the rule
// was made; it is the same on every device, so that every device renders the same
// image.
inline constexpr int kPilotPassSamples = 16;

// The pilot's samples: f·N, at least two per technique, raised for `method` as the two
// constants above say.
int pilotSamples(double pilotFraction, int spp, int techniqueCount, Method method);

// The sizes of `method`'s pilot and the following stages, summing to spp. Throws
// InputError if the budget cannot hold a pilot of two samples per technique plus one
// stage.
std::vector<int> stageSizes(double pilotFraction, int stages, int spp, int techniqueCount, Method method);

// One stage's kernel time, and the cost model's prediction of it, made before it ran.
struct StageTiming {
  int samples = 0;  // per pixel
  bool keptStatistics = false;
  std::optional<double> predictedKernelSeconds;  // adaptive methods only
  double kernelSeconds = 0;
};

struct Rendering {
  RgbImage image;
  std::vector<double> variance;              // per pixel: estimated variance of the luminance estimate
  std::vector<double> alpha;                 // [pixel·M + k]: the share of the pixel's samples technique k took
  size_t fallbackPixels = 0;                 // pixels where an allocation rule fell back (alloc/Allocation.h)
  size_t flooredPixels = 0;                  // pixels where a stage's counts were raised to one per technique
  size_t skippedPixels = 0;                  // pixels that the skip rule kept at equal weights in every stage
  OptimalWeightsFallbacks weightsFallbacks;  // --weights optimal: pixels a stage left at the balance heuristic
  int stageCount = 1;
  // exact: the image's efficiency gain over equal counts that the pilot predicts for
  // the stages after it (alloc/WholeImageRule.h), and whether the render then kept
  // equal counts for all of them
  std::optional<double> predictedGain;
  bool keptEqualCounts = false;
  double meanPilotWeight = 0;          // staged methods: the pilot's weight in the estimate, mean over pixels
  double statisticsBytesPerPixel = 0;  // running sums and stored samples kept for the allocation
  double kernelSeconds = 0;            // device time of the sampling kernels (profiling events)
  double allocationSeconds = 0;        // reading statistics back and allocating
  double hostSeconds = 0;              // everything else: planning, transfers, reductions
  double wallSeconds = 0;
  std::vector<DeviceShare> devices;    // where it ran (sampling/TiledSampler.h for several)
  double imbalanceSeconds = 0;         // several devices: Σ over stages of last finish − first finish
  std::vector<StageTiming> stages;     // the pilot (or the oracle's probe) first
  std::optional<CostModel> costModel;  // adaptive methods: what they allocated with
};

// Renders every pixel with `spp` samples: fixed splits in one stage, adaptive methods
// in a pilot and `stages` batches. With optimal weights every stage after the first
// uses them, a fixed split then also running a pilot of options.pilotFraction. The sampler must keep what the method
// needs (samplerConfigFor); whatever it took before is forgotten (StageSampler::reset).
Rendering render(StageSampler& sampler, Method method, const AdaptiveOptions& options, int spp, uint64_t seed);

// What a sampler keeps for `method` in a scene of `techniqueCount` techniques: its stored
// samples are sized for that count's stages.
SamplerConfig samplerConfigFor(Method method, Estimator fixedSplitEstimator, int spp, const AdaptiveOptions& options,
                               int techniqueCount);

}  // namespace misalloc
