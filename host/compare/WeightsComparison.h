#pragma once
// [Kon19]'s optimal weights as a dimension of `compare` (`--weights balance,optimal`):
// each scene and pdf runs once per weights, as a case of its own whose label ends in
// "-optimal-weights", so that every table shows each method with each; this file adds
// the comparison of the two weights at the same counts and pdf.
#include <string>
#include <vector>

#include "compare/Comparison.h"
#include "compare/SummaryTables.h"

namespace misalloc {

// Comma-separated weights (parseMisWeights), each once; throws InputError.
std::vector<MisWeights> parseWeightsList(const std::string& list);

// Each case once per weights, in that order. The optimal-weights cases leave out, saying
// why, the methods that refuse them at some budget (render/RunChecks.h): a single
// technique, σ/√c's count-independent weights.
std::vector<CompareCase> casesPerWeights(const std::vector<CompareCase>& cases, const std::vector<MisWeights>& weights,
                                         const std::vector<Method>& methods, const std::vector<int>& budgets,
                                         const AdaptiveOptions& adaptive);

// Rows = (method, pdf), columns = scenes and their geometric means: at `budget`, the
// balance heuristic's MSE over the optimal weights' (equal samples, the same counts
// and pdf) and how many times longer the balance heuristic needs, in wall time, to
// reach the optimal weights' error (equal time: speedUpOver, on the balance curve).
TextTable weightsTable(const Summary& summary, int budget);

// The tables at speedUpBudgets, in Markdown; empty unless some case ran with optimal
// weights and its balance twin with them.
std::string weightsMarkdown(const Summary& summary);

}  // namespace misalloc
