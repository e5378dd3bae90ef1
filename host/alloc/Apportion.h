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

// Every technique takes at least one sample of each stage. The count-independent
// estimator ([SHS16] eq. 26) needs one of each technique for all its terms, and with the
// BRDF split into lobes the specular lobe alone does not cover the diffuse lobe's
// support. With the balance heuristic and M = 2 either technique alone is unbiased, but
// a pilot that misses a sun (rooitou_park: 0.1 % of the texels) can drive α_envmap to
// 0; the estimate then rests on rare BRDF hits of the sun, unbiased yet so heavy-tailed
// that it comes out low almost always (tests/test_stability.cpp). True if it changed
// the counts: the report counts those pixels.
bool floorCounts(int* counts, int m);

}  // namespace misalloc
