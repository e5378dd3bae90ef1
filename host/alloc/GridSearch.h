#pragma once
// Havran & Sbert's "exact" allocation ([HS14] Sec. 4.2, Algorithm 1): for every pixel,
// the weight combination out of a grid of U that is best according to the pixel's
// samples so far, by one of two rules. GridSearch runs kernels/gridsearch.cl on a
// device; GridSearchReference is its C++ reference and OpenMP peer.

#include <CL/opencl.hpp>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "alloc/Allocation.h"
#include "cl/Device.h"
#include "sampling/Stage.h"

namespace misalloc {

// How [HS14] Alg. 1 line 13 picks the combination l₀.
enum class GridRule {
  // As written: the l whose λ_{j,l} = Λ_{j,l} / Σ_j Λ_{j,l} (eq. 4.16) has maximum
  // entropy, i.e. is closest to the equal Λ_j of the optimum.
  MaxEntropy,
  // The l with the least estimated cost × variance of the estimator actually used:
  // (Σ_k c_k α_k) · Σ_j α_j (ν_j − μ_j²), the multi-sample balance heuristic ([SHS16] eq. 21).
  MinCostVariance,
};

// U, `--grid-u`: one pass of the kernel (16 · MA_GRID_VECTORS). For M = 2 its best α
// is within 0.02 % of the variance at the best of 160 on the papers' 1D examples, for
// M = 3 within 2.7 % (tests/test_exact.cpp), below the noise of a pixel's estimates.
inline constexpr int kDefaultGridSize = 80;

// The U weight combinations of [HS14] Alg. 1 line 4, every α_k > 0. For a lattice
// resolution r they are α_k = (a_k + 1/M) / (r + 1) over the integer a ≥ 0 with
// Σ_k a_k = r: C(r + M − 1, M − 1) points, r chosen to make that closest to the
// requested size (exactly U for M = 2, where α_0 = (l + ½)/U). The search weighs the
// stored samples' columns (SampleColumns): with share columns, a combination puts α_0
// in the column of the share that a stage of that α_0 samples with (bankShareOf,
// kernels/envmap.h) and 0 in the other shares', so that each α_0 is judged by the pdf
// it would run.
struct WeightGrid {
  SampleColumns columns{0};
  std::vector<float> alpha;  // [l·C + c]: the weight of column c
  std::vector<float> cost;   // [l]: Σ_k c_k α_{k,l}, the cost per sample at l

  int size() const { return static_cast<int>(cost.size()); }
  // α_k of combination l: the sum of technique k's columns.
  double techniqueWeight(int l, int k) const;
};

// Throws std::invalid_argument for M outside 2..kMaxTechniques, columns beyond it, a
// size < 1 or an invalid cost (validateCosts; one per technique).
WeightGrid makeWeightGrid(SampleColumns columns, int approximateSize, const std::vector<double>& costs);

// The `-D` options that compile kernels/gridsearch.cl for these columns, with rule (b)
// ranking the variance of [Kon19]'s optimal weights where `optimalWeights`. The grid, its
// rule and the pooling are kernel arguments: one program serves them all.
std::string gridSearchKernelOptions(SampleColumns columns, bool optimalWeights);

// What a search keeps per pixel from run to run: Σ g and Σ g² for every column and
// combination (the grid padded to whole passes) where it keeps running sums, the
// summary of the samples, and the last search's scores and scale for the pooled
// selection; with optimal weights also P's pairs per combination.
std::size_t gridSearchBytesPerPixel(SampleColumns columns, int gridSize, bool runningSums, bool optimalWeights);

// Rule (b)'s selection over neighbourhoods (Pooling.h says why) and the skip
// rule, for the pixels of a width × height image: each pixel takes the combination
// with the least Σ_q (Σ_k c_k α_k) V_q over the ranked pixels q within `radius`, and
// keeps equal weights where that is not at least the fraction `minGain` below its
// value at the combination nearest to equal weights: there the predicted gain does
// not pay for the overhead of adapting. For radius > 0 the pixel itself is left out
// of its window, so that its selection and predicted variance ratio do not depend on
// its own samples. Radius 0 and minGain 0 select as rule (b) alone, but for the skip
// where no combination beats equal weights.
struct PooledSelection {
  int width = 0, height = 0;
  int radius = 0;
  double minGain = 0;
};

struct GridSearchResult {
  std::vector<Allocation> allocations;  // per pixel; equal weights where it fell back or skipped
  std::vector<int> selected;            // l₀ per pixel, −1 where it fell back or skipped
  std::vector<unsigned char> skipped;   // per pixel: 1 where the skip rule kept equal weights
  // Per pixel, V(equal)/V(α) of the multi-sample estimator as the pixel's neighbours
  // predict it, α the selected weights: 1 where the selection did not come from the
  // neighbours alone (no pooling, radius 0, no ranked neighbour) or skipped.
  std::vector<float> varianceRatio;
  // Per pixel at [2·pixel + {0, 1}], the variance of equal weights and of the weights it
  // runs, by its own samples, which did not choose them (kernels/gridsearch.h,
  // heldOutVariance): NaN where its selection did not come from the neighbours alone,
  // 0 where its own samples could not be searched. Only a pooled selection writes them.
  std::vector<float> heldOutVariance;
  double seconds = 0;  // kernel time (profiling event), or the reference's wall time

  int fallbackCount() const;
};

// Runs kernels/gridsearch.cl for `pixelCount` pixels over makeWeightGrid(columns,
// gridSize, ·); the program is built and its first launch compiled once. Each run adds
// the samples stored since the previous one to every pixel's running sums
// (gridSearchBytesPerPixel, on the device) and selects by all the samples added so far.
// Without `runningSums` (a render with one search) nothing is kept, which saves their
// memory and the search the time of writing them, and a second search with samples
// since reset() throws std::logic_error.
// A scratch buffer of taken · (C + 1) floats per pixel, for the new samples as the sums
// read them, is kept from run to run. The allocations it returns are per technique.
// With `optimalWeights`, rule (b) ranks each combination by the variance of the
// estimator with [Kon19]'s optimal weights at those counts (kernels/gridsearch.h,
// optimalVarianceScore), and rule (a) is refused.
class GridSearch {
 public:
  // `surfaces`: per pixel, its surface (Scene::surfaces), within which a pooled selection
  // pools; empty: one surface. Throws std::invalid_argument for columns that
  // makeWeightGrid rejects, share columns with optimal weights, a grid size < 1, or
  // surfaces of another pixel count.
  GridSearch(const Device& device, SampleColumns columns, int pixelCount, int gridSize = kDefaultGridSize,
             bool runningSums = true, bool optimalWeights = false, const std::vector<int32_t>& surfaces = {});

  // Throws std::invalid_argument for a layout that does not match the columns, the
  // pixel count or the buffer, taken > capacity, costs that makeWeightGrid rejects,
  // rule (a) with share columns (it ranks each column by its own samples), or pooling
  // with rule (a) or over an image that does not match the pixel count.
  GridSearchResult run(const cl::Buffer& samples, const StoredSampleLayout& layout, const std::vector<double>& costs,
                       GridRule rule = GridRule::MinCostVariance,
                       const std::optional<PooledSelection>& pooling = std::nullopt);
  // Forgets the samples added so far.
  void reset();
  // Makes and writes the buffer that searches of up to `samples` taken per pixel prepare
  // their samples in, so that the first does not pay its page faults, as the sums' and
  // scores' buffers are written when the search is made.
  void reserve(int samples);

 private:
  const Device& device_;
  SampleColumns columns_;
  int pixelCount_, gridSize_;
  bool runningSums_, optimalWeights_;
  bool added_ = false;  // a search since reset() added samples
  cl::Kernel kernel_, poolKernel_;
  cl::Buffer summaries_, sums_, prepared_, scores_, scales_, surfaces_;
  std::size_t preparedFloats_ = 0;
};

// The same search with plain loops, one pixel per OpenMP iteration and the weight
// combinations innermost, on the same stored samples (host memory), keeping the same
// running sums in host memory.
class GridSearchReference {
 public:
  GridSearchReference(SampleColumns columns, int pixelCount, int gridSize = kDefaultGridSize, bool runningSums = true,
                      bool optimalWeights = false, const std::vector<int32_t>& surfaces = {});
  ~GridSearchReference();

  GridSearchResult run(const std::vector<float>& samples, const StoredSampleLayout& layout,
                       const std::vector<double>& costs, GridRule rule = GridRule::MinCostVariance,
                       const std::optional<PooledSelection>& pooling = std::nullopt);
  void reset();

 private:
  struct RunningSums;  // kernels/gridsearch.h's types, which this header does not include
  SampleColumns columns_;
  int pixelCount_, gridSize_;
  bool runningSums_, optimalWeights_;
  bool added_ = false;
  std::vector<int32_t> surfaces_;  // one per pixel
  std::unique_ptr<RunningSums> running_;
};

}  // namespace misalloc
