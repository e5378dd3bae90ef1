#include "alloc/GridSearch.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "Constants.h"
#include "KernelCode.h"
#include "cl/KernelArgs.h"

namespace misalloc {

static_assert(MA_GRID_MAX_TECHNIQUES == kMaxTechniques);

namespace {

// B, the float16s of weight combinations that share one pass over a pixel's samples
// and one division per sample (MA_BATCH_QUOTIENTS): 2B accumulator chains, and the
// 160 combinations of the default grid in two passes.
constexpr int kGridVectors = 5;
constexpr int kPass = 16 * kGridVectors;

// Work-items per group. PoCL keeps every work-item's private arrays of a group at
// once; with the group size left to it (thousands) they overflow its stack.
constexpr int kLocalSize = 4;
constexpr int kPoolLocalSize = 8;  // selectPooled: one work-item per pixel

void checkColumns(SampleColumns columns) {
  if (columns.techniqueCount < 2 || columns.count() > kMaxTechniques || columns.shareColumns < 0)
    throw std::invalid_argument(fmt::format("grid search: {} techniques in {} columns; it needs 2 to {}",
                                            columns.techniqueCount, columns.count(), kMaxTechniques));
}

// [Kon19]'s variance is the system of the techniques' pdfs; a share column is a pdf the
// stage may not run (the sampler stores share columns with balance weights only).
void checkColumns(SampleColumns columns, bool optimalWeights) {
  checkColumns(columns);
  if (optimalWeights && columns.shareColumns > 0)
    throw std::invalid_argument("grid search: optimal weights on samples with share columns");
}

void checkLayout(const StoredSampleLayout& layout, SampleColumns columns, int pixelCount, std::size_t availableFloats) {
  if (layout.columns != columns.count())
    throw std::invalid_argument(
        fmt::format("grid search: samples of {} columns, search built for {}", layout.columns, columns.count()));
  if (layout.pixelCount != pixelCount)
    throw std::invalid_argument(
        fmt::format("grid search: samples of {} pixels, search built for {}", layout.pixelCount, pixelCount));
  if (layout.pixelCount < 0 || layout.taken < 0 || layout.taken > layout.capacity)
    throw std::invalid_argument(fmt::format("grid search: {} pixels, {} of {} samples taken", layout.pixelCount,
                                            layout.taken, layout.capacity));
  if (availableFloats < layout.floatCount())
    throw std::invalid_argument(fmt::format("grid search: the samples hold {} floats, the layout needs {}",
                                            availableFloats, layout.floatCount()));
}

// Appends every a ≥ 0 with Σ_k a_k = remaining over the techniques k ≥ first, in
// lexicographic order, as the weights (a_k + 1/M) / (r + 1).
void appendLattice(std::vector<int>& a, int first, int remaining, int resolution, std::vector<float>& alpha) {
  int m = static_cast<int>(a.size());
  if (first == m - 1) {
    a[first] = remaining;
    for (int k = 0; k < m; ++k) alpha.push_back(float((a[k] + 1.0 / m) / (resolution + 1)));
    return;
  }
  for (a[first] = 0; a[first] <= remaining; ++a[first])
    appendLattice(a, first + 1, remaining - a[first], resolution, alpha);
}

// C(r + M − 1, M − 1): the lattice points of resolution r.
long latticeSize(int techniqueCount, int resolution) {
  long n = 1;
  for (int k = 1; k < techniqueCount; ++k) n = n * (resolution + k) / k;
  return n;
}

int closestResolution(int techniqueCount, int approximateSize) {
  int r = 0;
  while (latticeSize(techniqueCount, r + 1) <= approximateSize) ++r;
  long below = latticeSize(techniqueCount, r), above = latticeSize(techniqueCount, r + 1);
  return above - approximateSize <= approximateSize - below ? r + 1 : r;
}

// The grid size rounded up to whole passes.
int paddedGridSize(int gridSize) { return (gridSize + kPass - 1) / kPass * kPass; }

// Floats of running sums per pixel: Σ g and Σ g² for every technique and combination
// of the grid makeWeightGrid makes (and validates), padded to whole passes, and with
// optimal weights P's pairs.
// The grid's combinations (not its costs): makeWeightGrid with unit costs.
WeightGrid gridFor(SampleColumns columns, int gridSize) {
  return makeWeightGrid(columns, gridSize, std::vector<double>(columns.techniqueCount, 1.0));
}

std::size_t runningSumFloats(SampleColumns columns, int gridSize, bool optimalWeights) {
  return std::size_t(kern::sumRows(columns.count(), optimalWeights ? 1 : 0)) *
         paddedGridSize(gridFor(columns, gridSize).size());
}

// The grid's combination nearest to α_k = 1/M, against which the skip rule weighs.
int nearestEqual(const WeightGrid& grid) {
  const int m = grid.columns.techniqueCount;
  int best = 0;
  double bestDistance = INFINITY;
  for (int l = 0; l < grid.size(); ++l) {
    double d = 0;
    for (int k = 0; k < m; ++k) d += (grid.techniqueWeight(l, k) - 1.0 / m) * (grid.techniqueWeight(l, k) - 1.0 / m);
    if (d < bestDistance) bestDistance = d, best = l;
  }
  return best;
}

// The entropy rule's Λ_j ([HS14] eq. 4.16) are the balance heuristic's.
void checkRule(GridRule rule, bool optimalWeights) {
  if (optimalWeights && rule == GridRule::MaxEntropy)
    throw std::invalid_argument("grid search: rule (a) ranks the balance heuristic, not the optimal weights");
}

// A search that keeps no running sums cannot add to those of a search before it.
void checkRunningSums(bool runningSums, bool added) {
  if (!runningSums && added)
    throw std::logic_error("grid search: a second search since reset() on a search that keeps no running sums");
}

// Rule (a) ranks each column by its own samples' sums; a share column that the stage
// did not sample with has none.
void checkRule(GridRule rule, SampleColumns columns) {
  if (rule == GridRule::MaxEntropy && columns.shareColumns > 0)
    throw std::invalid_argument("grid search: rule (a) on samples with share columns");
}

// A search's surfaces, one per pixel: those given, or one surface.
std::vector<int32_t> surfacesOfPixels(const std::vector<int32_t>& surfaces, int pixelCount) {
  const std::size_t pixels = std::size_t(std::max(0, pixelCount));
  if (surfaces.empty()) return std::vector<int32_t>(pixels, 0);
  if (surfaces.size() != pixels)
    throw std::invalid_argument(fmt::format("grid search: {} surfaces for {} pixels", surfaces.size(), pixels));
  return surfaces;
}

void checkPooling(const std::optional<PooledSelection>& pooling, GridRule rule, int pixelCount) {
  if (!pooling) return;
  if (rule == GridRule::MaxEntropy) throw std::invalid_argument("grid search: rule (a) cannot pool its selection");
  if (std::size_t(pooling->width) * std::size_t(std::max(0, pooling->height)) != std::size_t(pixelCount) ||
      pooling->radius < 0 || !(pooling->minGain >= 0 && pooling->minGain < 1))
    throw std::invalid_argument(fmt::format("grid search: pooling over {}x{} pixels, radius {}, gain {} for {} pixels",
                                            pooling->width, pooling->height, pooling->radius, pooling->minGain,
                                            pixelCount));
}

// Per pixel α (a float per column), l₀ and fallback bits, as the kernels write them.
struct SelectionArrays {
  std::vector<float> alpha;
  std::vector<int> selected;
  std::vector<unsigned> fallbacks;
  std::vector<unsigned char> skipped;
  std::vector<float> varianceRatio;
  std::vector<float> heldOutVariance;  // [2·pixel + {0: equal weights, 1: the weights run}]
};

// The allocations per technique: a technique's weight is the sum of its columns'; a
// pixel that skipped takes α_k = 1/M (the kernels write 1/C per column).
GridSearchResult toResult(const SelectionArrays& a, SampleColumns columns) {
  const std::size_t pixels = a.selected.size();
  const int m = columns.techniqueCount, c = columns.count();
  GridSearchResult result;
  result.selected = a.selected;
  result.skipped = a.skipped;
  result.varianceRatio = a.varianceRatio;
  result.heldOutVariance = a.heldOutVariance;
  result.allocations.reserve(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    std::vector<double> alpha(m, 0.0);
    for (int column = 0; column < c; ++column) alpha[columns.techniqueOf(column)] += a.alpha[p * c + column];
    if (a.skipped[p]) alpha.assign(m, 1.0f / m);
    result.allocations.push_back(a.fallbacks[p] != 0 ? equalFallback(m, a.fallbacks[p]) : Allocation{alpha});
  }
  return result;
}

// The grid as the passes read it: α_{k,l} at [k · paddedSize + l] and the cost per
// sample at [l], the size rounded up to whole passes with copies of the last
// combination, which are summed but never selected.
struct LaneGrid {
  int paddedSize;
  std::vector<float> alpha, cost;
};

LaneGrid laneGrid(const WeightGrid& grid) {
  const int m = grid.columns.count(), u = grid.size();
  LaneGrid lanes{paddedGridSize(u), {}, {}};
  lanes.alpha.resize(std::size_t(m) * lanes.paddedSize);
  lanes.cost.resize(lanes.paddedSize);
  for (int l = 0; l < lanes.paddedSize; ++l) {
    int last = std::min(l, u - 1);
    for (int k = 0; k < m; ++k) lanes.alpha[k * lanes.paddedSize + l] = grid.alpha[last * m + k];
    lanes.cost[l] = grid.cost[last];
  }
  return lanes;
}

std::vector<float> toFloats(const std::vector<double>& values) {
  return std::vector<float>(values.begin(), values.end());
}

int kernelRule(GridRule rule) { return rule == GridRule::MaxEntropy ? MA_RULE_MAX_ENTROPY : MA_RULE_MIN_COST_VARIANCE; }

// The inputs of one reference search, shared by every pixel.
struct SearchSetup {
  const float* samples;
  StoredSampleLayout layout;
  WeightGrid grid;
  LaneGrid lanes;
  std::vector<float> cost;  // c_k
  int rule;
  bool optimalWeights;  // rule (b) by the variance with [Kon19]'s optimal weights
};

// Adds the new samples to the running sums at `sums` (sumRows rows) for every
// combination l, the sums first brought to the current scale: the kernel's loadSums,
// loadPair, sumTechnique or sumMixture and storeSums, storePair as plain loops, with the
// same operations in the same order. Rule (a): Σ g and Σ g² of each technique's samples
// ([HS14] Alg. 1 line 8); rule (b): M_j and S2 (kernels/gridsearch.h, costVarianceScore)
// and, with optimal weights, P (optimalVarianceScore).
template <int M>
void sumPixel(const SearchSetup& setup, const kern::PixelSummary& added, const float* prepared, float rescale,
              float* sums) {
  const int padded = setup.lanes.paddedSize, every = setup.optimalWeights ? 1 : 0;
  const float* alpha = setup.lanes.alpha.data();
  const float rescale2 = rescale * rescale;
  for (int j = 0; j < M; ++j) {
    float* s = sums + kern::runningSumIndex(j, 0, 0, padded);
    float* s2 = sums + kern::runningSumIndex(j, 1, 0, padded);
    for (int l = 0; l < padded; ++l) {
      s[l] = rescale == 0.0f ? 0.0f : s[l] * rescale;
      s2[l] = rescale == 0.0f ? 0.0f : s2[l] * rescale2;
    }
  }
  if (every)
    for (int pair = 0; pair < MA_PAIRS(M); ++pair)
      if (rescale == 0.0f) std::fill_n(sums + kern::pairSumIndex(pair, 0, M, padded), padded, 0.0f);
  // numerator/p_α of sample x at the 16 combinations of lane block l0 + 16 v, batched as
  // the kernel batches them.
  auto quotients = [&](const float* x, float numerator, int l0, int lane, float(&g)[kGridVectors]) {
    float p[kGridVectors];
    for (int v = 0; v < kGridVectors; ++v) {
      int l = l0 + 16 * v + lane;
      p[v] = alpha[l] * x[1];
      for (int k = 1; k < M; ++k) p[v] = std::fma(alpha[k * padded + l], x[1 + k], p[v]);
    }
    MA_BATCH_QUOTIENTS(float, kGridVectors, numerator, p, g);
  };
  // add(l, q) for q = numerator/p_α of sample x at every combination l, lanes vectorised.
  auto forEachQuotient = [&](const float* x, float numerator, auto add) {
    for (int l0 = 0; l0 < padded; l0 += kPass)
#pragma omp simd
      for (int lane = 0; lane < 16; ++lane) {
        float g[kGridVectors];
        quotients(x, numerator, l0, lane, g);
        for (int v = 0; v < kGridVectors; ++v) add(l0 + 16 * v + lane, g[v]);
      }
  };
  if (setup.rule == MA_RULE_MAX_ENTROPY) {
    for (int j = 0; j < M; ++j) {
      float* s = sums + kern::runningSumIndex(j, 0, 0, padded);
      float* s2 = sums + kern::runningSumIndex(j, 1, 0, padded);
      const float* x = prepared + kern::preparedFirst(added, j, every) * (M + 1);
      for (int i = 0; i < kern::preparedCount(added, j, every); ++i, x += M + 1)
        forEachQuotient(x, x[0], [&](int l, float g) {
          s[l] += g;
          s2[l] = std::fma(g, g, s2[l]);
        });
    }
    return;
  }
  float stageMix[M];
  kern::stageMixture(M, added, stageMix);
  float* sumS2 = sums + kern::runningSumIndex(0, 1, 0, padded);
  float* sumM[M];
  for (int j = 0; j < M; ++j) sumM[j] = sums + kern::runningSumIndex(j, 0, 0, padded);
  float* sumP[MA_PAIRS(M)];
  for (int pair = 0; pair < MA_PAIRS(M); ++pair) sumP[pair] = sums + kern::pairSumIndex(pair, 0, M, padded);
  const float* x = prepared;
  for (int i = 0; i < kern::preparedFirst(added, M, every); ++i, x += M + 1) {
    float r[M];
    const float w = kern::mixtureWeights(M, stageMix, x, r);
    auto addMixture = [&](int l, float g) {
      sumS2[l] = std::fma(g, w, sumS2[l]);
      for (int j = 0; j < M; ++j) sumM[j][l] = std::fma(g, r[j], sumM[j][l]);
    };
    if (!every) {
      forEachQuotient(x, x[0], addMixture);
      continue;
    }
    forEachQuotient(x, 1.0f, [&](int l, float inverse) {
      int pair = 0;
      for (int a = 0; a < M; ++a) {
        const float t = inverse * x[1 + a];
        for (int b = a; b < M; ++b, ++pair) sumP[pair][l] = std::fma(t, r[b], sumP[pair][l]);
      }
      addMixture(l, inverse * x[0]);
    });
  }
}

void sumPixel(const SearchSetup& setup, const kern::PixelSummary& added, const float* prepared, float rescale,
              float* sums) {
  switch (setup.layout.columns) {
    case 2:
      return sumPixel<2>(setup, added, prepared, rescale, sums);
    case 3:
      return sumPixel<3>(setup, added, prepared, rescale, sums);
    default:
      return sumPixel<4>(setup, added, prepared, rescale, sums);
  }
}

// The best l₀ by the pixel's sums ([HS14] Alg. 1 line 13), −1 if none could be ranked;
// every combination's score goes to `scores`.
int bestCombination(const SearchSetup& setup, const kern::PixelSummary& all, const float* sums, float* scores) {
  const int m = setup.layout.columns, padded = setup.lanes.paddedSize;
  float invCount[kMaxTechniques], bestScore = -INFINITY;
  for (int j = 0; j < m; ++j) invCount[j] = 1.0f / all.count[j];
  const float invTotal = 1.0f / kern::sampleCount(m, all);
  int best = -1;
  for (int l = 0; l < setup.grid.size(); ++l) {
    float g1[kMaxTechniques], g2[kMaxTechniques], p[MA_PAIRS(kMaxTechniques)];
    for (int j = 0; j < m; ++j) {
      g1[j] = sums[kern::runningSumIndex(j, 0, l, padded)];
      g2[j] = sums[kern::runningSumIndex(j, 1, l, padded)];
    }
    for (int pair = 0; setup.optimalWeights && pair < MA_PAIRS(m); ++pair)
      p[pair] = sums[kern::pairSumIndex(pair, l, m, padded)];
    float score = setup.optimalWeights && setup.rule == MA_RULE_MIN_COST_VARIANCE
                      ? kern::optimalVarianceScore(m, setup.grid.cost[l], g1, g2[0], p, invTotal)
                      : kern::gridScore(setup.rule, m, &setup.grid.alpha[l * m], setup.grid.cost[l], setup.cost.data(),
                                        g1, g2, invCount, invTotal);
    scores[l] = score;
    if (score > bestScore) {
      bestScore = score;
      best = l;
    }
  }
  return best;
}

// [HS14] Alg. 1 lines 5–13 for one pixel, as the kernel's gridSearch does it: adds the
// new samples to `summary` and the running sums at `sums`, then selects, writing the
// scores and the scale of the sums.
void searchPixel(const SearchSetup& setup, int pixel, std::vector<float>& prepared, kern::PixelSummary& summary,
                 float* sums, SelectionArrays& out, float* scores, float& scale) {
  const int m = setup.layout.columns;
  const float* pixelSamples = setup.samples + kern::storedSampleIndex(pixel, 0, 0, setup.layout.capacity, m);
  kern::PixelSummary added = kern::emptySummary();
  for (int i = 0; i < setup.layout.taken; ++i)
    kern::summariseSample(&added, pixelSamples, m, setup.grid.columns.shareColumns, i);
  const kern::PixelSummary all = kern::mergeSummaries(summary, added);
  unsigned fallbacks = kern::pixelFallbacks(m, all, setup.rule);
  int best = -1;
  scale = kern::sampleScale(all);
  // Pixels that cannot be ranked yet keep their sums for the searches to come.
  const int every = setup.optimalWeights ? 1 : 0;
  if (kern::hasSums(all, every)) {
    int next[kMaxTechniques];
    for (int j = 0; j < m; ++j) next[j] = kern::preparedFirst(added, j, every);
    for (int i = 0; i < setup.layout.taken; ++i)
      kern::prepareSample(pixelSamples, m, i, scale, every, next, prepared.data());
    sumPixel(setup, added, prepared.data(), kern::sumsRescale(summary, scale, every), sums);
    if (fallbacks == 0) best = bestCombination(setup, all, sums, scores);
  }
  if (fallbacks == 0 && best < 0)
    fallbacks = setup.rule == MA_RULE_MAX_ENTROPY ? kFallbackSingularSystem : kFallbackNonFinite;
  summary = all;
  out.selected[pixel] = fallbacks == 0 ? best : -1;
  out.fallbacks[pixel] = fallbacks;
  for (int k = 0; k < m; ++k)
    out.alpha[std::size_t(pixel) * m + k] =
        fallbacks == 0 ? setup.lanes.alpha[k * setup.lanes.paddedSize + best] : 1.0f / m;
}

// The pooled score of combination l over window w: Σ_q score_q,l · (scaleMin/scale_q)²
// over the window's pooled pixels q in row-major order, one fma chain, as a lane of the
// kernel selectPooled sums it.
float pooledScore(const std::vector<float>& scores, const std::vector<float>& scales,
                  const std::vector<unsigned>& fallbacks, const std::vector<int32_t>& surfaces, kern::PoolWindow w,
                  int width, int paddedSize, float scaleMin, int l) {
  float sum = 0.0f;
  for (int y = w.y0; y <= w.y1; ++y)
    for (int x = w.x0; x <= w.x1; ++x) {
      int q = y * width + x;
      if (kern::pools(w, q, fallbacks[q], surfaces[q]))
        sum = std::fma(scores[std::size_t(q) * paddedSize + l], kern::poolingFactor(scaleMin, scales[q]), sum);
    }
  return sum;
}

// The kernel selectPooled for one pixel, with the combinations in a plain loop: each
// combination's pooled score is the same fma chain as the kernel's lane.
void selectPooledPixel(const SearchSetup& setup, const PooledSelection& pooling, const std::vector<int32_t>& surfaces,
                       int equal, const std::vector<float>& scores, const std::vector<float>& scales,
                       const SelectionArrays& in, int pixel, SelectionArrays& out) {
  const int m = setup.layout.columns, padded = setup.lanes.paddedSize;
  kern::PoolWindow w = kern::poolWindow(pixel, pooling.width, pooling.height, pooling.radius, surfaces[pixel]);
  float scaleMin = INFINITY;
  for (int y = w.y0; y <= w.y1; ++y)
    for (int x = w.x0; x <= w.x1; ++x) {
      const int q = y * pooling.width + x;
      if (kern::pools(w, q, in.fallbacks[q], surfaces[q])) scaleMin = std::fmin(scaleMin, scales[q]);
    }
  int best = -1, skipped = 0;
  float ratio = 1.0f;
  if (scaleMin < INFINITY) {
    float top = -INFINITY;
    for (int l = 0; l < setup.grid.size(); ++l) {
      float score = pooledScore(scores, scales, in.fallbacks, surfaces, w, pooling.width, padded, scaleMin, l);
      if (score > top) top = score, best = l;
    }
    float sumD = 0.0f, sumD2 = 0.0f, count = 0.0f;
    for (int y = w.y0; y <= w.y1; ++y)
      for (int x = w.x0; x <= w.x1; ++x) {
        int q = y * pooling.width + x;
        if (!kern::pools(w, q, in.fallbacks[q], surfaces[q])) continue;
        const float* s = scores.data() + std::size_t(q) * padded;
        float d = (s[best] - s[equal]) * kern::poolingFactor(scaleMin, scales[q]);
        sumD += d;
        sumD2 = std::fma(d, d, sumD2);
        count += 1.0f;
      }
    float pooledEqual = pooledScore(scores, scales, in.fallbacks, surfaces, w, pooling.width, padded, scaleMin, equal);
    skipped = kern::skipsAdapting(top, pooledEqual, float(pooling.minGain), sumD, sumD2, count);
    if (!skipped && w.self >= 0)
      ratio = kern::pooledVarianceRatio(top, setup.lanes.cost[best], pooledEqual, setup.lanes.cost[equal]);
  }
  for (int k = 0; k < m; ++k)
    out.alpha[std::size_t(pixel) * m + k] =
        best < 0 ? in.alpha[std::size_t(pixel) * m + k] : (skipped ? 1.0f / m : setup.lanes.alpha[k * padded + best]);
  out.selected[pixel] = best < 0 ? in.selected[pixel] : (skipped ? -1 : best);
  out.fallbacks[pixel] = best < 0 ? in.fallbacks[pixel] : 0u;
  out.skipped[pixel] = (unsigned char)skipped;
  out.varianceRatio[pixel] = ratio;
  float heldOutEqual = NAN, heldOutRun = NAN;
  if (best >= 0 && w.self >= 0) {
    const float* own = scores.data() + std::size_t(pixel) * padded;
    const int run = skipped ? equal : best;
    const bool searched = in.fallbacks[pixel] == 0u;
    heldOutEqual = searched ? kern::heldOutVariance(own[equal], setup.lanes.cost[equal], scales[pixel]) : 0.0f;
    heldOutRun = searched ? kern::heldOutVariance(own[run], setup.lanes.cost[run], scales[pixel]) : 0.0f;
  }
  out.heldOutVariance[2 * std::size_t(pixel)] = heldOutEqual;
  out.heldOutVariance[2 * std::size_t(pixel) + 1] = heldOutRun;
}

SelectionArrays selectionArrays(int pixels, int m) {
  return SelectionArrays{std::vector<float>(std::size_t(pixels) * m),
                         std::vector<int>(pixels),
                         std::vector<unsigned>(pixels),
                         std::vector<unsigned char>(pixels, 0),
                         std::vector<float>(pixels, 1.0f),
                         std::vector<float>(2 * std::size_t(pixels), NAN)};
}

}  // namespace

double WeightGrid::techniqueWeight(int l, int k) const {
  double weight = 0;
  for (int column = 0; column < columns.count(); ++column)
    if (columns.techniqueOf(column) == k) weight += alpha[std::size_t(l) * columns.count() + column];
  return weight;
}

WeightGrid makeWeightGrid(SampleColumns columns, int approximateSize, const std::vector<double>& costs) {
  checkColumns(columns);
  const int m = columns.techniqueCount, c = columns.count();
  validateCosts(costs, m);
  if (approximateSize < 1) throw std::invalid_argument("grid search: the grid needs at least one combination");
  int resolution = closestResolution(m, approximateSize);
  std::vector<float> lattice;
  std::vector<int> a(m);
  appendLattice(a, 0, resolution, resolution, lattice);
  WeightGrid grid;
  grid.columns = columns;
  for (std::size_t l = 0; l < lattice.size() / m; ++l) {
    const float* alpha = &lattice[l * m];
    // Technique 0's weight in its share's column where there are share columns.
    const int envmapColumn = columns.shareColumns > 0 ? kern::bankShareOf(columns.shareColumns, alpha[0]) : 0;
    double meanCost = 0;
    for (int column = 0; column < c; ++column) {
      const int k = columns.techniqueOf(column);
      grid.alpha.push_back(k == 0 && column != envmapColumn ? 0.0f : alpha[k]);
    }
    for (int k = 0; k < m; ++k) meanCost += costs[k] * alpha[k];
    grid.cost.push_back(float(meanCost));
  }
  return grid;
}

std::string gridSearchKernelOptions(SampleColumns columns, bool optimalWeights) {
  return fmt::format(
      "-cl-std=CL1.2 -DMA_TECHNIQUES={} -DMA_SHARE_COLUMNS={} -DMA_GRID_VECTORS={} "
      "-DMA_GRID_OPTIMAL_WEIGHTS={}",
      columns.count(), columns.shareColumns, kGridVectors, optimalWeights ? 1 : 0);
}

std::size_t gridSearchBytesPerPixel(SampleColumns columns, int gridSize, bool runningSums, bool optimalWeights) {
  const std::size_t scoreFloats = paddedGridSize(gridFor(columns, gridSize).size()) + 1;  // and the scale
  const std::size_t sumFloats = runningSums ? runningSumFloats(columns, gridSize, optimalWeights) : 0;
  return (sumFloats + scoreFloats) * sizeof(float) + sizeof(kern::PixelSummary);
}

int GridSearchResult::fallbackCount() const {
  return static_cast<int>(
      std::count_if(allocations.begin(), allocations.end(), [](const Allocation& a) { return a.usedFallback(); }));
}

GridSearch::GridSearch(const Device& device, SampleColumns columns, int pixelCount, int gridSize, bool runningSums,
                       bool optimalWeights, const std::vector<int32_t>& surfaces)
    : device_(device),
      columns_(columns),
      pixelCount_(pixelCount),
      gridSize_(gridSize),
      runningSums_(runningSums),
      optimalWeights_(optimalWeights) {
  checkColumns(columns, optimalWeights);
  cl::Program program = buildProgram(device, "gridsearch.cl", gridSearchKernelOptions(columns, optimalWeights));
  kernel_ = cl::Kernel(program, "gridSearch");
  poolKernel_ = cl::Kernel(program, "selectPooled");
  // OpenCL buffers cannot be empty.
  const std::size_t pixels = std::max(1, pixelCount);
  summaries_ = cl::Buffer(device.context, CL_MEM_READ_WRITE, pixels * sizeof(kern::PixelSummary));
  // Only pixels with hasSums read their sums, so reset() leaves them; they are written
  // once here so that the first search does not pay a page fault per 4 KiB of them.
  // Without running sums the kernel reads and writes none: one float stands in.
  const std::size_t sumBytes =
      (runningSums ? pixels * runningSumFloats(columns, gridSize, optimalWeights) : 1) * sizeof(float);
  sums_ = cl::Buffer(device.context, CL_MEM_READ_WRITE, sumBytes);
  device.queue.enqueueFillBuffer(sums_, cl_uchar(0), 0, sumBytes);
  const std::size_t scoreBytes = pixels * paddedGridSize(gridFor(columns, gridSize).size()) * sizeof(float);
  scores_ = cl::Buffer(device.context, CL_MEM_READ_WRITE, scoreBytes);
  device.queue.enqueueFillBuffer(scores_, cl_uchar(0), 0, scoreBytes);
  scales_ = cl::Buffer(device.context, CL_MEM_READ_WRITE, pixels * sizeof(float));
  std::vector<int32_t> surfaceOf = surfacesOfPixels(surfaces, pixelCount);
  surfaceOf.resize(pixels);
  surfaces_ =
      cl::Buffer(device.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, pixels * sizeof(int32_t), surfaceOf.data());
  reset();
  // PoCL compiles a kernel for its work-group size at the first launch: pay that here,
  // with a search of no samples, not inside the first timed one.
  cl::Buffer noSamples(device.context, CL_MEM_READ_ONLY, sizeof(float));
  run(noSamples, StoredSampleLayout{pixelCount, columns.count(), 0, 0},
      std::vector<double>(columns.techniqueCount, 1.0), GridRule::MinCostVariance,
      PooledSelection{pixelCount, 1, 0, 0});
}

void GridSearch::reset() {
  added_ = false;
  // An all-zero PixelSummary is emptySummary().
  device_.queue.enqueueFillBuffer(summaries_, cl_uchar(0), 0, summaries_.getInfo<CL_MEM_SIZE>());
  device_.queue.finish();
}

// The prepared samples' buffer is kept from run to run: a new one costs the kernel a
// page fault per 4 KiB, and page faults do not scale across threads.
void GridSearch::reserve(int samples) {
  const std::size_t floats =
      std::max<std::size_t>(1, paddedPixelCount(std::size_t(pixelCount_)) * std::size_t(samples) * (columns_.count() + 1));
  if (floats <= preparedFloats_) return;
  prepared_ = cl::Buffer(device_.context, CL_MEM_READ_WRITE, floats * sizeof(float));
  device_.queue.enqueueFillBuffer(prepared_, cl_uchar(0), 0, floats * sizeof(float));
  device_.queue.finish();
  preparedFloats_ = floats;
}

GridSearchResult GridSearch::run(const cl::Buffer& samples, const StoredSampleLayout& layout,
                                 const std::vector<double>& costs, GridRule rule,
                                 const std::optional<PooledSelection>& pooling) {
  checkLayout(layout, columns_, pixelCount_, samples.getInfo<CL_MEM_SIZE>() / sizeof(float));
  checkRule(rule, columns_);
  checkPooling(pooling, rule, pixelCount_);
  checkRule(rule, optimalWeights_);
  checkRunningSums(runningSums_, added_);
  added_ = added_ || layout.taken > 0;
  WeightGrid grid = makeWeightGrid(columns_, gridSize_, costs);
  const int m = columns_.count(), pixels = layout.pixelCount;
  GridSearchResult result;
  if (pixels == 0) return result;
  auto upload = [&](std::vector<float> data) {
    return cl::Buffer(device_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, data.size() * sizeof(float),
                      data.data());
  };
  LaneGrid lanes = laneGrid(grid);
  cl::Buffer gridLanes = upload(lanes.alpha), gridCost = upload(lanes.cost), cost = upload(toFloats(costs));
  reserve(layout.taken);
  cl::Buffer alphaOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * m * sizeof(float));
  cl::Buffer selectedOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(cl_int));
  cl::Buffer fallbacksOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(cl_uint));
  bindKernelArgs(kernel_, samples, cl_int(layout.capacity), cl_int(layout.taken), cl_int(pixels), gridLanes, gridCost,
                 cl_int(grid.size()), cl_int(lanes.paddedSize), cost, cl_int(kernelRule(rule)), prepared_, summaries_,
                 sums_, cl_int(runningSums_), alphaOut, selectedOut, fallbacksOut, scores_, scales_);
  cl::Event done;
  const int blocks = int(paddedPixelCount(std::size_t(pixels)) / kPixelBlock);
  device_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange,
                                     cl::NDRange((blocks + kLocalSize - 1) / kLocalSize * kLocalSize),
                                     cl::NDRange(kLocalSize), nullptr, &done);
  done.wait();
  result.seconds = eventSeconds(done);

  SelectionArrays out = selectionArrays(pixels, m);
  cl::Buffer alphaFinal = alphaOut, selectedFinal = selectedOut, fallbacksFinal = fallbacksOut;
  if (pooling) {
    alphaFinal = cl::Buffer(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * m * sizeof(float));
    selectedFinal = cl::Buffer(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(cl_int));
    fallbacksFinal = cl::Buffer(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(cl_uint));
    cl::Buffer skippedOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels));
    cl::Buffer ratioOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(float));
    cl::Buffer heldOut(device_.context, CL_MEM_WRITE_ONLY, 2 * std::size_t(pixels) * sizeof(float));
    bindKernelArgs(poolKernel_, scores_, scales_, alphaOut, selectedOut, fallbacksOut, surfaces_,
                   cl_int(pooling->width), cl_int(pooling->height), cl_int(pooling->radius), gridLanes, gridCost,
                   cl_int(grid.size()), cl_int(lanes.paddedSize), cl_int(nearestEqual(grid)),
                   cl_float(pooling->minGain), alphaFinal, selectedFinal, fallbacksFinal, skippedOut, ratioOut,
                   heldOut);
    cl::Event pooled;
    device_.queue.enqueueNDRangeKernel(
        poolKernel_, cl::NullRange,
        cl::NDRange((std::size_t(pixels) + kPoolLocalSize - 1) / kPoolLocalSize * kPoolLocalSize),
        cl::NDRange(kPoolLocalSize), nullptr, &pooled);
    pooled.wait();
    result.seconds += eventSeconds(pooled);
    device_.queue.enqueueReadBuffer(skippedOut, CL_FALSE, 0, pixels, out.skipped.data());
    device_.queue.enqueueReadBuffer(ratioOut, CL_FALSE, 0, pixels * sizeof(float), out.varianceRatio.data());
    device_.queue.enqueueReadBuffer(heldOut, CL_FALSE, 0, 2 * pixels * sizeof(float), out.heldOutVariance.data());
  }
  device_.queue.enqueueReadBuffer(alphaFinal, CL_FALSE, 0, out.alpha.size() * sizeof(float), out.alpha.data());
  device_.queue.enqueueReadBuffer(selectedFinal, CL_FALSE, 0, pixels * sizeof(cl_int), out.selected.data());
  device_.queue.enqueueReadBuffer(fallbacksFinal, CL_TRUE, 0, pixels * sizeof(cl_uint), out.fallbacks.data());
  double seconds = result.seconds;
  result = toResult(out, columns_);
  result.seconds = seconds;
  return result;
}

// What the reference keeps from run to run, as the kernel keeps it on the device.
struct GridSearchReference::RunningSums {
  std::vector<kern::PixelSummary> summaries;
  std::vector<float> sums;            // runningSumIndex
  std::vector<float> scores, scales;  // the last search's, as the kernel keeps them
};

GridSearchReference::GridSearchReference(SampleColumns columns, int pixelCount, int gridSize, bool runningSums,
                                         bool optimalWeights, const std::vector<int32_t>& surfaces)
    : columns_(columns),
      pixelCount_(pixelCount),
      gridSize_(gridSize),
      runningSums_(runningSums),
      optimalWeights_(optimalWeights),
      surfaces_(surfacesOfPixels(surfaces, pixelCount)) {
  checkColumns(columns, optimalWeights);
  running_ = std::make_unique<RunningSums>();
  if (runningSums)
    running_->sums.resize(std::size_t(std::max(0, pixelCount)) * runningSumFloats(columns, gridSize, optimalWeights));
  reset();
}

GridSearchReference::~GridSearchReference() = default;

void GridSearchReference::reset() {
  added_ = false;
  running_->summaries.assign(std::max(0, pixelCount_), kern::emptySummary());
}

GridSearchResult GridSearchReference::run(const std::vector<float>& samples, const StoredSampleLayout& layout,
                                          const std::vector<double>& costs, GridRule rule,
                                          const std::optional<PooledSelection>& pooling) {
  checkLayout(layout, columns_, pixelCount_, samples.size());
  checkRule(rule, columns_);
  checkPooling(pooling, rule, pixelCount_);
  checkRule(rule, optimalWeights_);
  checkRunningSums(runningSums_, added_);
  added_ = added_ || layout.taken > 0;
  WeightGrid grid = makeWeightGrid(columns_, gridSize_, costs);
  SearchSetup setup{samples.data(), layout, grid, laneGrid(grid), toFloats(costs), kernelRule(rule), optimalWeights_};
  const int m = columns_.count(), pixels = layout.pixelCount, padded = setup.lanes.paddedSize;
  const std::size_t pixelSums = std::size_t(kern::sumRows(m, optimalWeights_ ? 1 : 0)) * padded;
  std::vector<float>& scores = running_->scores;
  std::vector<float>& scales = running_->scales;
  scores.resize(std::size_t(pixels) * padded);
  scales.resize(pixels);
  SelectionArrays searched = selectionArrays(pixels, m);
  auto start = std::chrono::steady_clock::now();
#pragma omp parallel
  {
    std::vector<float> prepared(std::size_t(layout.taken) * (m + 1));
    std::vector<float> scratch(runningSums_ ? 0 : pixelSums);  // the sums of a search that keeps none
#pragma omp for schedule(dynamic, 16)
    for (int pixel = 0; pixel < pixels; ++pixel)
      searchPixel(setup, pixel, prepared, running_->summaries[pixel],
                  runningSums_ ? running_->sums.data() + pixel * pixelSums : scratch.data(), searched,
                  scores.data() + std::size_t(pixel) * padded, scales[pixel]);
  }
  SelectionArrays selection = searched;
  if (pooling) {
    const int equal = nearestEqual(grid);
#pragma omp parallel for schedule(dynamic, 64)
    for (int pixel = 0; pixel < pixels; ++pixel)
      selectPooledPixel(setup, *pooling, surfaces_, equal, scores, scales, searched, pixel, selection);
  }
  GridSearchResult result = toResult(selection, columns_);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace misalloc
