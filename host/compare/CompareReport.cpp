#include "compare/CompareReport.h"

#include "AtomicFile.h"
#include "JsonText.h"
#include "compare/EnvmapPdfComparison.h"
#include "compare/ErrorTimePlot.h"
#include "compare/HtmlIndex.h"
#include "compare/SummaryTables.h"
#include "compare/WeightsComparison.h"

namespace misalloc {

void writeCompareReport(const Summary& summary, const std::string& outDir) {
  writeFileAtomically(outDir + "/summary.md", summaryMarkdown(summary));
  writeFileAtomically(outDir + "/summary.csv", summaryCsv(summary));
  writeFileAtomically(outDir + "/summary.json", jsonText(summaryJson(summary)));
  writeFileAtomically(outDir + "/budgets.csv", budgetsCsv(summary));
  for (const SceneGroup& scene : groupByScene(summary))
    writeFileAtomically(outDir + "/" + plotFileName(scene.label), errorTimePlotSvg(scene));
  writeFileAtomically(outDir + "/index.html", indexHtml(summary));
}

ComparisonReport writeComparisonReport(const Comparison& comparison, const CompareOptions& options,
                                       const std::string& outDir) {
  ComparisonReport report{summarize(comparison, options), "", ""};
  writeCompareReport(report.summary, outDir);
  report.envmapPdfTables = envmapPdfMarkdown(report.summary);
  if (!report.envmapPdfTables.empty()) writeFileAtomically(outDir + "/envmap_pdfs.md", report.envmapPdfTables);
  report.weightsTables = weightsMarkdown(report.summary);
  if (!report.weightsTables.empty()) writeFileAtomically(outDir + "/weights.md", report.weightsTables);
  return report;
}

}  // namespace misalloc
