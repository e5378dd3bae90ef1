#include "compare/SummaryTables.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "JsonText.h"
#include "report/Report.h"

namespace misalloc {
namespace {

// Rows = methods, one column per scene; `cell` gives a scene's entry and its number
// (lower is better when `lowerBetter`), NaN where there is none. The best entry of
// each column is marked bold.
template <typename Cell>
TextTable methodTable(const Summary& s, bool lowerBetter, Cell cell) {
  TextTable table{{"method"}, {}};
  for (const CaseSummary& c : s.cases) table.header.push_back(c.info.label);
  std::vector<double> best(s.cases.size(), lowerBetter ? std::numeric_limits<double>::infinity() : 0.0);
  for (size_t i = 0; i < s.cases.size(); ++i)
    for (Method m : s.methods) {
      double v = cell(s.cases[i], m).second;
      if (v == v) best[i] = lowerBetter ? std::min(best[i], v) : std::max(best[i], v);
    }
  for (Method m : s.methods) {
    std::vector<TableCell> row{{methodName(m), false}};
    for (size_t i = 0; i < s.cases.size(); ++i) {
      auto [text, v] = cell(s.cases[i], m);
      row.push_back({text, v == best[i]});
    }
    table.rows.push_back(row);
  }
  return table;
}

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

std::pair<std::string, double> rmseCell(const Summary& s, const CaseSummary& c, Method m) {
  const MethodSummary* ms = c.find(m);
  const BudgetStats* b = ms ? ms->at(s.tableBudget) : nullptr;
  if (!b) return {"–", kNone};
  return {fmt::format("{:.2f} ± {:.2f}", b->rmseX1000, b->rmseSpreadX1000), b->rmseX1000};
}

std::pair<std::string, double> speedUpCell(const CaseSummary& c, Method m, int budget) {
  const MethodSummary* ms = c.find(m);
  const BudgetStats* b = ms ? ms->at(budget) : nullptr;
  if (!b || !b->speedUp) return {"–", kNone};
  return {(b->speedUp->extrapolated ? "~" : "") + fmt::format("{:.2f}×", b->speedUp->value), b->speedUp->value};
}

std::pair<std::string, double> timeCell(const Summary& s, const CaseSummary& c, Method m) {
  const MethodSummary* ms = c.find(m);
  const BudgetStats* b = ms ? ms->at(s.tableBudget) : nullptr;
  if (!b) return {"–", kNone};
  return {fmt::format("{:.3f} ({:.3f} + {:.3f})", b->wallSeconds, b->kernelSeconds, b->allocationSeconds),
          b->wallSeconds};
}

nlohmann::json curveValueJson(const CurveValue& v) { return {{"value", v.value}, {"extrapolated", v.extrapolated}}; }

nlohmann::json budgetJson(const BudgetStats& b) {
  return {{"spp", b.budget},
          {"repeats", b.repeats},
          {"mse", b.mse},
          {"rmse_x1000", b.rmseX1000},
          {"rmse_spread_x1000", b.rmseSpreadX1000},
          {"relative_mse", b.relativeMse},
          {"time_s", timeSplitJson(b.wallSeconds, b.kernelSeconds, b.allocationSeconds, b.hostSeconds)},
          {"efficiency", b.efficiency},
          {"mean_alpha", b.meanAlpha},
          {"speed_up_over_equal", b.speedUp ? curveValueJson(*b.speedUp) : nlohmann::json()}};
}

}  // namespace

std::string escapeHtml(const std::string& text) {
  std::string out;
  for (char ch : text) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

TextTable rmseTable(const Summary& s) {
  return methodTable(s, true, [&](const CaseSummary& c, Method m) { return rmseCell(s, c, m); });
}

TextTable speedUpTable(const Summary& s, int budget) {
  return methodTable(s, false, [&](const CaseSummary& c, Method m) { return speedUpCell(c, m, budget); });
}

TextTable timeTable(const Summary& s) {
  return methodTable(s, true, [&](const CaseSummary& c, Method m) { return timeCell(s, c, m); });
}

TextTable equalTimeTable(const CaseSummary& c) {
  TextTable table{{"method"}, {}};
  for (double t : c.commonSeconds) table.header.push_back(fmt::format("{:.3g} s", t));
  for (const MethodSummary& m : c.methods) {
    if (m.equalTimeRmseX1000.empty()) continue;
    std::vector<TableCell> row{{methodName(m.method), false}};
    for (const CurveValue& v : m.equalTimeRmseX1000) row.push_back({formatCurveValue(v, 2), false});
    table.rows.push_back(row);
  }
  return table;
}

std::string markdown(const TextTable& table) {
  std::string out = "|";
  for (const std::string& h : table.header) out += " " + h + " |";
  out += "\n|";
  for (size_t i = 0; i < table.header.size(); ++i) out += "---|";
  out += "\n";
  for (const auto& row : table.rows) {
    out += "|";
    for (const TableCell& c : row) out += " " + (c.best ? "**" + c.text + "**" : c.text) + " |";
    out += "\n";
  }
  return out;
}

std::string html(const TextTable& table) {
  std::string out = "<table>\n<tr>";
  for (const std::string& h : table.header) out += "<th>" + escapeHtml(h) + "</th>";
  out += "</tr>\n";
  for (const auto& row : table.rows) {
    out += "<tr>";
    for (const TableCell& c : row)
      out += c.best ? "<td><b>" + escapeHtml(c.text) + "</b></td>" : "<td>" + escapeHtml(c.text) + "</td>";
    out += "</tr>\n";
  }
  return out + "</table>\n";
}

std::vector<int> speedUpBudgets(const Summary& s) {
  if (s.budgets.back() == s.tableBudget) return {s.tableBudget};
  return {s.tableBudget, s.budgets.back()};
}

std::string formatCurveValue(const CurveValue& v, int decimals) {
  return (v.extrapolated ? "~" : "") + fmt::format("{:.{}f}", v.value, decimals);
}

// The reference's own variance as a share of the smallest MSE measured at `budget`: how
// much of the raw errors was the reference's, at most.
double referenceShare(const CaseSummary& c, int budget) {
  double smallest = HUGE_VAL;
  for (const MethodSummary& m : c.methods)
    if (const BudgetStats* b = m.at(budget); b && b->mse > 0) smallest = std::min(smallest, b->mse);
  return c.info.referenceVariance / smallest;
}

std::string summaryMarkdown(const Summary& s) {
  const CaseSummary* first = s.cases.empty() ? nullptr : &s.cases.front();
  std::string out = "# misalloc compare\n\n";
  if (s.interrupted) out += "**Interrupted: the tables hold only the budgets that every repeat finished.**\n\n";
  if (first) {
    int repeats = 0;
    for (const MethodSummary& m : first->methods)
      if (!m.budgets.empty()) repeats = m.budgets.front().repeats;
    out += fmt::format(
        "Device: {}. Budgets (spp): {}. Repeats with independent seeds: {}. Times are medians over the repeats.\n\n",
        first->info.device, fmt::join(s.budgets, ", "), repeats);
    for (const CaseSummary& c : s.cases)
      for (const LeftOutMethod& l : c.info.leftOut)
        out += fmt::format("Not run in {}: {} ({}).\n\n", c.info.label, methodName(l.method), l.why);
    for (const CaseSummary& c : s.cases)
      out += fmt::format(
          "Reference of {}: {}; its own variance is {:.2f} % of the smallest error at {} spp (aim: at "
          "most 2 %), and is taken out of every error below.\n\n",
          c.info.label, c.info.referenceSource, 100 * referenceShare(c, s.budgets.back()), s.budgets.back());
  }
  out += fmt::format(
      "## RMSE×1000 at {} spp\n\nThe layout of [HS14] Table 5.2: the RMSE of RGB over the image against the true "
      "image, ×1000, as the mean over repeats ± their spread (sample standard deviation). Every error, speed-up and "
      "equal-time figure here is reference-corrected: the mean of (x − r)² minus the reference's own variance "
      "(runs.csv also has the raw error). Bold: the best of the column.\n\n",
      s.tableBudget);
  out += markdown(rmseTable(s));
  for (int budget : speedUpBudgets(s)) {
    out += fmt::format(
        "\n## Speed-up over equal at equal error, {} spp\n\nHow many times longer `equal` needs to reach the error "
        "each method reaches with {} spp, in wall-clock time per render (sampling, allocation and host). Above 1: the "
        "method pays off; `~`: read off `equal`'s curve past its measured range.\n\n",
        budget, budget);
    out += markdown(speedUpTable(s, budget));
  }
  out += fmt::format(
      "\n## Time per render at {} spp\n\nWall seconds (sampling kernels + allocation); the rest is host "
      "work.\n\n",
      s.tableBudget);
  out += markdown(timeTable(s));
  out +=
      "\n## Equal-time error per scene\n\nRMSE×1000 of each method interpolated (log–log) at equal's median render "
      "times; `~` marks values continued past the method's measured times with the Monte Carlo law MSE ∝ 1/t.\n";
  for (const CaseSummary& c : s.cases) out += "\n### " + c.info.label + "\n\n" + markdown(equalTimeTable(c));
  if (s.costModel)
    out += fmt::format(
        "\n## Cost model\n\nThe adaptive methods allocate with a model of each stage's kernel time, calibrated once "
        "per device, kernel build and scene and cached (runs.json: `costs_source`). Over the {} stages of the adaptive "
        "renders, its "
        "prediction made before the stage ran was off by |predicted/measured − 1| = {:.1f} % (median), {:.1f} % at "
        "worst (runs.json: `stages`).\n",
        s.costModel->stages, 100 * s.costModel->median, 100 * s.costModel->worst);
  return out;
}

std::string summaryCsv(const Summary& s) {
  std::string out = "method";
  for (const CaseSummary& c : s.cases) out += "," + c.info.label;
  out += "\n";
  for (Method m : s.methods) {
    out += methodName(m);
    for (const CaseSummary& c : s.cases) {
      const MethodSummary* ms = c.find(m);
      const BudgetStats* b = ms ? ms->at(s.tableBudget) : nullptr;
      out += b ? fmt::format(",{:.4f}", b->rmseX1000) : ",";
    }
    out += "\n";
  }
  return out;
}

std::string budgetsCsv(const Summary& s) {
  std::string out =
      "case,method,spp,repeats,rmse_x1000,rmse_spread_x1000,relative_mse,wall_s,kernel_s,allocation_s,host_s,"
      "efficiency,speed_up_over_equal,speed_up_extrapolated\n";
  for (const CaseSummary& c : s.cases)
    for (const MethodSummary& m : c.methods)
      for (const BudgetStats& b : m.budgets)
        out += fmt::format("{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{}\n", c.info.label,
                           methodName(m.method), b.budget, b.repeats, b.rmseX1000, b.rmseSpreadX1000, b.relativeMse,
                           b.wallSeconds, b.kernelSeconds, b.allocationSeconds, b.hostSeconds, b.efficiency,
                           b.speedUp ? fmt::format("{:.6g}", b.speedUp->value) : "",
                           b.speedUp ? (b.speedUp->extrapolated ? "1" : "0") : "");
  return out;
}

nlohmann::json summaryJson(const Summary& s) {
  nlohmann::json cases = nlohmann::json::array();
  for (const CaseSummary& c : s.cases) {
    nlohmann::json methods = nlohmann::json::array();
    for (const MethodSummary& m : c.methods) {
      nlohmann::json budgets = nlohmann::json::array(), equalTime = nlohmann::json::array();
      for (const BudgetStats& b : m.budgets) budgets.push_back(budgetJson(b));
      for (const CurveValue& v : m.equalTimeRmseX1000) equalTime.push_back(curveValueJson(v));
      methods.push_back({{"method", methodName(m.method)},
                         {"budgets", budgets},
                         {"log_log_slope", optionalJson(m.slope)},
                         {"equal_time_rmse_x1000", equalTime}});
    }
    cases.push_back({{"label", c.info.label},
                     {"scene", c.info.scene},
                     {"costs_s_per_sample", c.info.costs},
                     {"costs_source", c.info.costSource},
                     {"reference", c.info.referenceSource},
                     {"reference_variance_share", referenceShare(c, s.budgets.back())},
                     {"device", c.info.device},
                     {"equal_time_seconds", c.commonSeconds},
                     {"methods", methods}});
  }
  nlohmann::json methods = nlohmann::json::array();
  for (Method m : s.methods) methods.push_back(methodName(m));
  nlohmann::json costModel;
  if (s.costModel)
    costModel = {{"stages", s.costModel->stages},
                 {"median_abs_relative_error", s.costModel->median},
                 {"worst_abs_relative_error", s.costModel->worst}};
  return {{"interrupted", s.interrupted},
          {"table_spp", s.tableBudget},
          {"budgets", s.budgets},
          {"methods", methods},
          {"cases", cases},
          {"cost_model", costModel}};
}

}  // namespace misalloc
