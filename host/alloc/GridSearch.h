#pragma once
// Havran & Sbert's "exact" allocation (000 Sec. 4.2, Algorithm 1): for every pixel,
// the weight combination out of a grid of U that is best according to the pixel's
// stored samples, by one of two rules. GridSearch runs kernels/gridsearch.cl on a
// device; gridSearchReference is its C++ reference and OpenMP peer.

#include <CL/opencl.hpp>
#include <cstddef>
#include <vector>

#include "alloc/Allocation.h"
#include "cl/Device.h"

namespace misalloc {

// How 000 Alg. 1 line 13 picks the combination l₀.
enum class GridRule {
  // As written: the l whose λ_{j,l} = Λ_{j,l} / Σ_j Λ_{j,l} (eq. 4.16) has maximum
  // entropy, i.e. is closest to the equal Λ_j of the optimum.
  MaxEntropy,
  // The l with the least estimated cost × variance of the estimator actually used:
  // (Σ_k c_k α_k) · Σ_j α_j (ν_j − μ_j²), the multi-sample balance heuristic (002 eq. 21).
  MinCostVariance,
};

inline constexpr int kDefaultGridSize = 160;  // U, `--grid-u`

// The U weight combinations of 000 Alg. 1 line 4, every α_k > 0. For a lattice
// resolution r they are α_k = (a_k + 1/M) / (r + 1) over the integer a ≥ 0 with
// Σ_k a_k = r: C(r + M − 1, M − 1) points, r chosen to make that closest to the
// requested size (exactly U for M = 2, where α_0 = (l + ½)/U).
struct WeightGrid {
  int techniqueCount = 0;
  std::vector<float> alpha;  // [l·M + k]
  std::vector<float> cost;   // [l]: Σ_k c_k α_{k,l}, the cost per sample at l

  int size() const { return static_cast<int>(cost.size()); }
};

// Throws std::invalid_argument for M outside 2..kMaxTechniques, a size < 1 or an
// invalid cost (validateCosts).
WeightGrid makeWeightGrid(int techniqueCount, int approximateSize, const std::vector<double>& costs);

// Where the stored samples are: the blocked float layout of kernels/stats.h
// (storedSampleIndex), `capacity` slots per pixel of which the first `taken` are filled
// for every pixel, pixels padded to a multiple of 16.
struct StoredSampleLayout {
  int pixelCount = 0;
  int techniqueCount = 0;
  int capacity = 0;
  int taken = 0;

  std::size_t floatCount() const;
};

struct GridSearchResult {
  std::vector<Allocation> allocations;  // per pixel; equal weights where it fell back
  std::vector<int> selected;            // l₀ per pixel, −1 where it fell back
  double seconds = 0;                   // kernel time (profiling event), or the reference's wall time

  int fallbackCount() const;
};

// Runs kernels/gridsearch.cl; the program is built once for M techniques. A scratch
// buffer of taken · (M + 1) floats per pixel, for the samples as the sums read them,
// is kept from run to run.
class GridSearch {
 public:
  GridSearch(const Device& device, int techniqueCount);

  // Throws std::invalid_argument for a layout that does not match M or the buffer,
  // taken > capacity, or what makeWeightGrid rejects.
  GridSearchResult run(const cl::Buffer& samples, const StoredSampleLayout& layout, const std::vector<double>& costs,
                       int gridSize = kDefaultGridSize, GridRule rule = GridRule::MinCostVariance);

 private:
  const Device& device_;
  int techniqueCount_;
  cl::Kernel kernel_;
  cl::Buffer prepared_;
  std::size_t preparedFloats_ = 0;
};

// The same search with plain loops, one pixel per OpenMP iteration and the weight
// combinations innermost, on the same stored samples (host memory).
GridSearchResult gridSearchReference(const std::vector<float>& samples, const StoredSampleLayout& layout,
                                     const std::vector<double>& costs, int gridSize = kDefaultGridSize,
                                     GridRule rule = GridRule::MinCostVariance);

}  // namespace misalloc
