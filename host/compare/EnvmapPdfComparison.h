#pragma once
// The envmap pdf as a dimension of `compare` (`--envmap-pdfs plain,compensated,...`,
// [Kar19]): each scene runs once per pdf, as a case of its own labelled by caseLabel,
// so that every table shows each method with each pdf; this file adds the comparison
// across pdfs, against equal-count MIS with the plain pdf.
#include <string>
#include <vector>

#include "compare/Summary.h"
#include "compare/SummaryTables.h"

namespace misalloc {

// Comma-separated pdfs (parseEnvmapPdf), each once; throws InputError.
std::vector<EnvmapPdf> parseEnvmapPdfList(const std::string& list);

// Each case once per pdf, in that order, relabelled with caseLabel.
std::vector<CompareCase> casesPerEnvmapPdf(const std::vector<CompareCase>& cases, const std::vector<EnvmapPdf>& pdfs);


// Rows = (method, pdf), columns = scenes and their geometric mean: the speed-up at equal
// error at `budget` over `equal` with the plain pdf of the same scene (speedUpOver).
TextTable envmapPdfSpeedUpTable(const Summary& summary, int budget);

// The tables at speedUpBudgets, in Markdown; empty unless the summary has cases that
// differ only in their pdf.
std::string envmapPdfMarkdown(const Summary& summary);

}  // namespace misalloc
