#pragma once
// [Kon19]'s optimal MIS weights between a render's stages: each pixel's coefficients
// a_c = A⁻¹ b_c of the next stage's weights (kernels/pixel.h, withOptimalWeights), from
// the running sums of the stages before it (kernels/stats.h, MA_STATS_OPTIMAL) pooled
// over the pixel's neighbourhood (Pooling.h). The estimator is unbiased for any a that
// does not depend on the stage's own samples, so a noisy or defective solve costs
// variance, never bias; where the system cannot be trusted the pixel keeps the balance
// heuristic (a = 0), and the report counts it.

#include <Eigen/Dense>
#include <cstddef>
#include <vector>

#include "sampling/StageStatistics.h"
#include "stats/PixelStats.h"

namespace misalloc {

// [Kon19]'s linear system for one pixel, count-free: with the stage's counts n_k = N α_k,
// A_ik = ∫ p_i p_k / Σ_j n_j p_j = Ã_ik/N and b_ci = ∫ f_c p_i / Σ_j n_j p_j = b̃_ci/N, so
// a_c = A⁻¹ b_c = Ã⁻¹ b̃_c whatever N. Estimated as Ã ≈ (1/m) Σ_x r(x) r(x)ᵀ and
// b̃_c ≈ (1/m) Σ_x (f_c/p_α)(x) r(x), r_i = p_i/p_α, over the m samples x summed, each
// with the mixture p_α of its own stage: a sample-weighted mean of the systems of the
// stages summed (exact where they share their fractions α, as equal's do; for exact, the
// pilot's system stands in for the allocated stage's: docs/methods.md).
struct OptimalWeightsSystem {
  double samples = 0;  // m
  Eigen::MatrixXd A;   // Ã, M × M, symmetric
  Eigen::MatrixXd b;   // b̃, M × 3: one column per colour channel
};

// A pixel's system from its running sums (`slots`, kernels/stats.h layout for `mask`,
// which holds MA_STATS_OPTIMAL): the sums of every technique's samples together.
OptimalWeightsSystem optimalWeightsSystem(const double* slots, unsigned mask, int techniqueCount);

// Why a pixel's stage keeps the balance heuristic. Bits: one pixel can report several
// stages' reasons.
enum OptimalWeightsFallback : unsigned {
  kWeightsSolved = 0,
  kWeightsTooFewSamples = 1,   // m < kMinSamplesPerTechnique · M
  kWeightsIllConditioned = 2,  // Ã's equilibrated form is singular within its sampling noise
  kWeightsNonFinite = 4,       // NaN or ∞ in the sums or the solution
  // With the optimal envmap pdf, the stage draws from another table of its bank (another
  // share, kernels/envmap.h: bankEntryOf) than the samples the weights would be solved
  // from: their p_0 is not the stage's.
  kWeightsOtherEnvmapTable = 8,
};

// The optimal pdf's share (bankEntryOf, for BRDF bin 0) that a stage with a pixel's
// counts [k] samples the envmap with, as the kernels compute it, or for the optimal pdf
// per pixel the bits of the share it builds its table for; −1 for a pdf that ignores α.
int envmapTableOf(const Scene& scene, const int32_t* counts);

// Each unknown of a channel's system wants about ten samples: the excess variance of
// coefficients fitted to m samples is about M/m of the residual's (least squares), 10 %
// at this bound.
inline constexpr double kMinSamplesPerTechnique = 10;

struct PixelCoefficients {
  std::vector<double> a;  // [c·M + k]; all 0 where it fell back
  unsigned fallback = kWeightsSolved;
};

// a_c = Ã⁻¹ b̃_c for the three channels, guarded. Ã is equilibrated to S = D Ã D with
// D = diag(Ã)^(-1/2), the Gram matrix of the techniques' pdfs under the measure 1/p_α
// with unit diagonal, whose conditioning says how nearly one pdf is a combination of
// the others whatever their scales (a sun's pdf is 10⁵ times a diffuse lobe's, which
// alone would make Ã's condition number 10⁵). Each entry of S is a mean of m samples,
// known to about 1/√m of its unit diagonal, so S's eigenvalues are known to about
// M/√m: the solve falls back where S's least eigenvalue is below that, i.e. where the
// condition number exceeds λ_max(S) √m / M, since a's component along that eigenvector
// would be noise amplified beyond the variance it could save. As λ_max(S) ≤ M, the
// bound keeps κ ≤ √m, and the kernel's float Σ_l a_l p_l loses at most about
// √m · 2⁻²⁴ to cancellation (6·10⁻⁵ at a million pooled samples).
PixelCoefficients solveOptimalWeights(const OptimalWeightsSystem& system);

// The least eigenvalue of S that solveOptimalWeights trusts, for m samples and M
// techniques.
double trustedEigenvalue(double samples, int techniqueCount);

// Every pixel's coefficients for the next stage.
struct StageCoefficients {
  std::vector<float> coefficients;      // [pixel·3M + c·M + k] (StagePlan::optimalCoefficients)
  std::vector<unsigned char> fallback;  // per pixel: OptimalWeightsFallback bits
};

// From the running sums of every stage a sampler took since its reset(), pooled over
// the (2·poolRadius + 1)² pixels around each pixel, itself included, for a stage split by
// `next` ([pixel·M + k]) after a first stage `first`: a pixel whose stage draws from
// another table of the optimal pdf's bank than its first stage keeps the balance
// heuristic. The sampler's config must keep MA_STATS_OPTIMAL.
StageCoefficients optimalCoefficients(StageStatistics& stages, int poolRadius, const StagePlan& first,
                                      const std::vector<int32_t>& next);

// One pixel's system at the fractions β of the stage its weights are for, from samples
// drawn with other mixtures: a sample x with pdfs p(x), luminance Y(x) and q(x) the
// mixture of its own stage adds p pᵀ/(p_β q) and Y p/(p_β q), a deterministic mixture's
// estimate of Ã(β) and b̃_Y(β) (kernels/gridsearch.h, costVarianceScore, weighs its
// samples alike).
// Plain arrays, not Eigen's dynamic matrices: a render adds every stored sample of
// each pixel's window, and a temporary per sample cost `exact` more than its search.
struct RetargetedSums {
  explicit RetargetedSums(const std::vector<double>& beta);
  void add(const double* pdfs, double luminance, double mixture);
  // The system at β, each channel's b̃_c(β)_i taken as b̃_Y(β)_i times the share b̃_c/b̃_Y
  // of technique i in `drawn` (the system at the fractions the samples were drawn with).
  OptimalWeightsSystem system(const OptimalWeightsSystem& drawn) const;

  int techniqueCount;
  double beta[kMaxTechniques] = {};
  double samples = 0;
  double A[kMaxTechniques][kMaxTechniques] = {};  // upper triangle
  double bY[kMaxTechniques] = {};
};

// The coefficients for a stage split by `next` ([pixel·M + k]), solved at its own
// fractions β rather than at those the samples were drawn with: from the samples that
// `stored` (the last stage, whose counts were stored.counts) left in the sampler's stored
// samples (technique, luminance, pdfs), each weighted as a deterministic mixture of its
// own stage, Σ_x h(x)/q(x) ≈ m ∫ h with q its stage's mixture, for h = p pᵀ/p_β and
// Y p/p_β, over the (2·poolRadius + 1)² pixels around each pixel, itself included, whose
// samples were drawn from the envmap table the stage draws from (the optimal pdf's bank);
// where the pixel's own were not, it keeps the balance heuristic. The
// samples carry luminance only: each channel's b̃_c(β)_i is b̃_Y(β)_i times the share
// b̃_c/b̃_Y of technique i in the running sums (MA_STATS_OPTIMAL) at the fractions the
// samples were drawn with, exact in luminance and wherever that share does not depend
// on the fractions. The grid search's allocations ([HS14] Algorithm 1: exact and the
// oracle), whose α ranks the optimal weights' variance at β (kernels/gridsearch.h,
// optimalVarianceScore), use them, so that α and the weights are chosen together.
StageCoefficients retargetedCoefficients(StageStatistics& stages, const StagePlan& stored,
                                         const std::vector<int32_t>& next, int poolRadius);

// The pixels whose stages kept the balance heuristic, over a render: how many, and how
// many for each reason.
struct OptimalWeightsFallbacks {
  std::size_t pixels = 0, tooFewSamples = 0, illConditioned = 0, nonFinite = 0, otherEnvmapTable = 0;
};

// `fallback`: per pixel, the OR of its stages' bits.
OptimalWeightsFallbacks countWeightsFallbacks(const std::vector<unsigned char>& fallback);

}  // namespace misalloc
