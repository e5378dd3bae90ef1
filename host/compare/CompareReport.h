#pragma once
#include <string>

#include "compare/Summary.h"

namespace misalloc {

// Writes a comparison's summary into `outDir`: summary.{md,csv,json}, budgets.csv,
// plot_<scene>.svg per scene and index.html, each atomically.
void writeCompareReport(const Summary& summary, const std::string& outDir);

// What a comparison writes once its runs are done: the summary (writeCompareReport)
// and, where it compares envmap pdfs, envmap_pdfs.md, where it compares weights,
// weights.md; the summary and those tables are returned for the console. An unsharded
// compare and the merge of its shards call it alike.
struct ComparisonReport {
  Summary summary;
  std::string envmapPdfTables;
  std::string weightsTables;  // optimal against balance weights (WeightsComparison.h); empty if not both ran
};
ComparisonReport writeComparisonReport(const Comparison& comparison, const CompareOptions& options,
                                       const std::string& outDir);

}  // namespace misalloc
