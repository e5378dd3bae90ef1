#pragma once
// The best mixture weights of a 1D example: what the allocation heuristics approximate.

#include <vector>

#include "paper/Example1D.h"
#include "paper/MixtureVariance.h"

namespace misalloc {

enum class VarianceModel {
  OneSample,    // [SHS16] eq. 35: the technique of each sample is drawn with probabilities α
  MultiSample,  // [SHS16] eq. 21: deterministic counts n_k = α_k N
};

VarianceValue mixtureVariance(const Example1D& example, VarianceModel model, const std::vector<double>& alpha);

struct OptimalMixture {
  std::vector<double> alpha;
  double variance;      // V(α)
  double inefficiency;  // (Σ_k c_k α_k) · V(α): cost × variance, the inverse of efficiency
  bool converged;
};

// Minimises (Σ_k c_k α_k)·V(α) over the simplex by the nonmonotone spectral projected
// gradient method (Birgin, Martínez & Raydan 2000), from equal weights, with exact
// gradients: ∂V/∂α_j = −E_j for one sample ([HS14] eq. 4.7) and, differentiating
// λ − Σ_i α_i m_i², −E_j − m_j² + 2 Σ_i α_i m_i B_ij for multi-sample. Steps that
// would leave the valid densities with finite variance are shortened, so an optimum on
// the edge of validity ([HS14] App. C) is approached from inside.
OptimalMixture minimiseInefficiency(const Example1D& example, VarianceModel model, const std::vector<double>& costs);

struct GridMinimum {
  std::vector<double> alpha;
  double variance;
  int points;            // grid points visited
  int notADensity;       // skipped: the mixture is negative somewhere (SignedDensity or Undefined)
  int infiniteVariance;  // skipped: V(α) = ∞
};

// The minimum of V over the α whose components are multiples of 1/divisions, as 000
// App. C searches with step 0.01, skipping mixtures that are no density or have an
// infinite variance.
GridMinimum gridMinimum(const Example1D& example, VarianceModel model, int divisions);

}  // namespace misalloc
