#pragma once
#include <string>

#include "compare/Summary.h"

namespace misalloc {

// Writes a comparison's summary into `outDir`: summary.{md,csv,json}, budgets.csv,
// plot_<scene>.svg per scene and index.html, each atomically.
void writeCompareReport(const Summary& summary, const std::string& outDir);

}  // namespace misalloc
