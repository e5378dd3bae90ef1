#pragma once
// The envmap pdf as a dimension of `compare` (`--envmap-pdfs plain,compensated,...`,
// [Kar19]): each scene runs once per pdf, as a case of its own labelled by caseLabel,
// so that every table shows each method with each pdf; this file adds the comparison
// across pdfs, against equal-count MIS with the plain pdf.
#include <map>
#include <string>
#include <vector>

#include "compare/Summary.h"
#include "compare/SummaryTables.h"

namespace misalloc {

// Comma-separated pdfs (parseEnvmapPdf), each once; throws InputError.
std::vector<EnvmapPdf> parseEnvmapPdfList(const std::string& list);

// Records, in each case with a pdf other than the plain one, the methods that are
// biased with that pdf at some budget but not with the plain pdf (envmap sampling alone
// with [Kar19]'s pdfs), so that the default pdfs run every method where it is unbiased.
// What is refused with the plain pdf too stays an error (validateCompareOptions).
void leaveOutBiasedMethods(std::vector<CompareCase>& cases, const std::vector<Method>& methods,
                           const std::vector<int>& budgets, const AdaptiveOptions& adaptive);

// The pdf a case asked for ("plain", "optimal", …).
std::string requestedPdf(const CaseInfo& info);
// The pdf and, where they are not the balance heuristic, the weights a case ran with:
// "plain", "optimal + optimal weights", … (compare/WeightsComparison.h).
std::string caseVariant(const CaseInfo& info);

// The cases of one scene, one per pdf and weights.
struct SceneGroup {
  std::string label;                                // the first case's
  std::map<std::string, const CaseSummary*> byPdf;  // by caseVariant
  std::vector<const CaseSummary*> cases;            // in the summary's order
};

// Cases grouped by scene, in first-seen order.
std::vector<SceneGroup> groupByScene(const Summary& summary);

// Each case once per pdf, in that order, relabelled with caseLabel.
std::vector<CompareCase> casesPerEnvmapPdf(const std::vector<CompareCase>& cases, const std::vector<EnvmapPdf>& pdfs);


// Rows = (method, pdf), columns = scenes and their geometric mean: the speed-up at equal
// error at `budget` over `equal` with the plain pdf of the same scene (speedUpOver).
TextTable envmapPdfSpeedUpTable(const Summary& summary, int budget);

// The tables at speedUpBudgets, in Markdown; empty unless the summary has cases that
// differ only in their pdf.
std::string envmapPdfMarkdown(const Summary& summary);

}  // namespace misalloc
