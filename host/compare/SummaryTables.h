#pragma once
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "compare/Summary.h"

namespace misalloc {

struct TableCell {
  std::string text;
  bool best = false;  // the best of its column: bold
};

// A table for Markdown and HTML alike.
struct TextTable {
  std::vector<std::string> header;
  std::vector<std::vector<TableCell>> rows;
};

std::string markdown(const TextTable& table);
// `text` with &, < and > as HTML entities.
std::string escapeHtml(const std::string& text);
std::string html(const TextTable& table);

// Rows = methods, columns = scenes ([HS14] Table 5.2): RMSE×1000 at the table budget as
// mean ± spread; the speed-up over equal at equal error at one budget; the time per
// render.
TextTable rmseTable(const Summary& summary);
TextTable speedUpTable(const Summary& summary, int budget);
// The budgets the summaries give speed-ups at: the table budget and the largest, where
// the fixed costs of the adaptive methods weigh least.
std::vector<int> speedUpBudgets(const Summary& summary);
TextTable timeTable(const Summary& summary);
// One scene: each method's RMSE×1000 at equal's render times (ErrorCurve::mseAt).
TextTable equalTimeTable(const CaseSummary& scene);

// The summary in the layout of [HS14] Table 5.2 (rows = methods, columns = scenes):
// RMSE×1000 at the table budget, then the speed-up over equal at equal error and the
// time per render; per scene, the equal-time errors.
std::string summaryMarkdown(const Summary& summary);

// Table 5.2 alone: method, then RMSE×1000 of each scene at the table budget.
std::string summaryCsv(const Summary& summary);

// Every (scene, method, budget) reduced over its repeats, one row each.
std::string budgetsCsv(const Summary& summary);

nlohmann::json summaryJson(const Summary& summary);

// "12.3" or "~12.3" for a value continued past the measured range (ErrorCurve).
std::string formatCurveValue(const CurveValue& v, int decimals);

}  // namespace misalloc
