#pragma once
// Running per-pixel sums from which the allocation rules estimate their statistics.
#include "KernelCode.h"

namespace misalloc {

// The largest M any rule supports, the grid search's (kernels/common.h): [SS23]'s
// Example 5 combines four techniques.
inline constexpr int kMaxTechniques = MA_GRID_MAX_TECHNIQUES;

// Sums over the samples X_kj drawn from one technique k. Every field is a double so
// the struct is a flat block of doubles that a kernel can accumulate in place.
struct TechniqueStats {
  double count = 0;                    // n_k
  double sumW = 0;                     // Σ w, w = f / p_k: the single-technique estimator of [HS14] eq. 4.18
  double sumW2 = 0;                    // Σ w²
  double sumBalance = 0;               // Σ b, b = f / Σ_l p_l: the F_ij of [SHS16] eq. 27
  double sumBalance2 = 0;              // Σ b²
  double sumF = 0;                     // F_k = Σ_j f(X_kj) ([SS23] eq. 18)
  double sumPdf[kMaxTechniques] = {};  // sumPdf[i] = P_ik = Σ_j p_i(X_kj) ([SS23] eq. 18)
};

// [HS14] eq. 6.19: the unbiased sample variance from running sums. Cancellation in
// Σg² − (Σg)²/n can leave a tiny negative number, which is reported as 0.
double sampleVariance(double sum, double sumSquares, double count);

// A sample variance this small relative to the squared mean is indistinguishable
// from 0: the cancellation above leaves a relative error of about n·ε ≈ 1e-12 for
// the 10⁴ samples a pixel can reach.
bool isZeroVariance(double variance, double mean);

struct PixelStats {
  // Throws std::invalid_argument unless 1 ≤ techniqueCount ≤ kMaxTechniques.
  explicit PixelStats(int techniqueCount);

  // Adds one sample X drawn from technique k with value f = f(X) and pdfs[i] = p_i(X)
  // for every technique i. A sample that would poison the sums (non-finite f or pdf,
  // a negative pdf, or f ≠ 0 where p_k(X) = 0, which has no finite weight) is not
  // added; it is counted in rejectedCount and add returns false. Both quotients are
  // taken as 0 where f = 0, so a failed sample (f = 0, p = 0) still counts.
  bool add(int k, double f, const double* pdfs);

  // False if any sum is NaN or infinite, e.g. in sums read back from a device.
  bool isFinite() const;

  int techniqueCount;
  TechniqueStats technique[kMaxTechniques];
  double rejectedCount = 0;
};

}  // namespace misalloc
