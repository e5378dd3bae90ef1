#pragma once
// From weights α to integer sample counts.

#include <vector>

namespace misalloc {

// Largest-remainder (Hamilton) apportionment: n_k = ⌊α_k N⌋, plus one for the
// techniques with the largest remainders α_k N − ⌊α_k N⌋ (ties: lower index) until
// Σ n_k = N exactly. alpha is normalised first. Throws std::invalid_argument on a
// negative or non-finite weight, weights summing to 0, or N < 0.
std::vector<int> apportionCounts(const std::vector<double>& alpha, int total);

// Counts for the next stage of a batched schedule (000 Alg. 1 line 15, Sec. 5.2):
// `taken` are the cumulative counts m_k so far, cumulativeTotal the total T after the
// stage. The stage's T − Σ m_k samples go to the techniques in proportion to their
// deficits max(0, α_k T − m_k), so the cumulative counts approach α·T without taking
// back samples already drawn. Throws std::invalid_argument if T < Σ m_k, a count is
// negative, the sizes differ, or alpha is invalid as above.
std::vector<int> nextStageCounts(const std::vector<int>& taken, const std::vector<double>& alpha, int cumulativeTotal);

}  // namespace misalloc
