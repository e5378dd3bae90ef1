#pragma once
// From weights α to integer sample counts.

#include <vector>

namespace misalloc {

// Largest-remainder (Hamilton) apportionment: n_k = ⌊α_k N⌋, plus one for the
// techniques with the largest remainders α_k N − ⌊α_k N⌋ (ties: lower index) until
// Σ n_k = N exactly. alpha is normalised first. Throws std::invalid_argument on a
// negative or non-finite weight, weights summing to 0, or N < 0.
std::vector<int> apportionCounts(const std::vector<double>& alpha, int total);
// The same for the m weights at `alpha` into `counts`, without allocating: a render
// apportions every pixel's stage.
void apportionCounts(const double* alpha, int m, int total, int* counts);

}  // namespace misalloc
