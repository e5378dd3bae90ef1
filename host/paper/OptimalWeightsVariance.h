#pragma once
// [Kon19]'s optimal MIS weights on a 1D example: their linear system by quadrature and
// the variance of the multi-sample estimator that uses them, N = 1.

#include <vector>

#include "paper/MixtureVariance.h"

namespace misalloc {

// With counts n_k = N α_k, A_ik = ∫ p_i p_k / Σ_j n_j p_j = Ã_ik/N and
// b_i = ∫ f p_i / Σ_j n_j p_j = b̃_i/N, Ã and b̃ taken against the mixture p_α.
struct OptimalWeightsSolution {
  VarianceValue variance;  // V_opt(α) for N = 1: ∫ f²/p_α − b̃ᵀ Ã⁻¹ b̃
  std::vector<double> a;   // Ã⁻¹ b̃, the weights' coefficients (empty unless Finite)
};

// The estimator Σ_k a_k + Σ_kj (f − Σ_l a_l p_l)(X_kj) / Σ_l n_l p_l(X_kj) has variance
// (1/N)[∫ (f − a·p)²/p_α − Σ_k α_k μ_k(a)²], μ_k(a) = ∫ p_k (f − a·p)/p_α = (b̃ − Ã a)_k
// ([SHS16] eq. 21 applied to the residual f − a·p). a = Ã⁻¹ b̃ zeroes every μ_k, and
// ∫ (f − a·p)²/p_α = ∫ f²/p_α − 2 aᵀb̃ + aᵀÃa leaves V_opt = (1/N)[∫ f²/p_α − b̃ᵀÃ⁻¹b̃],
// i.e. ∫ f²/Σ n p − bᵀA⁻¹b ([Kon19], docs/methods.md). It never exceeds the balance
// heuristic's (a = 0), ∫ f²/p_α − Σ_k α_k b̃_k²: Ã ⪯ diag(1/α) by Cauchy–Schwarz, so
// Ã⁻¹ ⪰ diag(α). For α on the simplex's interior; the status is mixtureMoments'.
OptimalWeightsSolution optimalWeightsVariance(const Example1D& example, const std::vector<double>& alpha);

}  // namespace misalloc
