#include "compare/WeightsComparison.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <sstream>

#include "Error.h"
#include "compare/EnvmapPdfComparison.h"
#include "render/RunChecks.h"

namespace misalloc {
namespace {

bool usable(const MethodSummary* m) {
  if (!m || m->budgets.empty()) return false;
  for (const BudgetStats& b : m->budgets)
    if (!(b.mse > 0 && std::isfinite(b.mse) && b.wallSeconds > 0)) return false;
  return true;
}

// The pdfs that some scene ran with both weights, in first-seen order.
std::vector<std::string> pairedPdfs(const std::vector<SceneGroup>& groups) {
  std::vector<std::string> pdfs;
  for (const SceneGroup& g : groups)
    for (const CaseSummary* c : g.cases)
      if (c->info.weights == MisWeights::Optimal && g.byPdf.count(requestedPdf(c->info)) &&
          std::find(pdfs.begin(), pdfs.end(), requestedPdf(c->info)) == pdfs.end())
        pdfs.push_back(requestedPdf(c->info));
  return pdfs;
}

}  // namespace

std::vector<MisWeights> parseWeightsList(const std::string& list) {
  std::vector<MisWeights> weights;
  std::stringstream items(list);
  for (std::string item; std::getline(items, item, ',');) {
    MisWeights w = parseMisWeights(item, "--weights");
    if (std::find(weights.begin(), weights.end(), w) != weights.end())
      throw InputError(fmt::format("--weights {}: {} is listed twice", list, item));
    weights.push_back(w);
  }
  if (weights.empty()) throw InputError("--weights: no weights");
  return weights;
}

std::vector<CompareCase> casesPerWeights(const std::vector<CompareCase>& cases, const std::vector<MisWeights>& weights,
                                         const std::vector<Method>& methods, const std::vector<int>& budgets,
                                         const AdaptiveOptions& adaptive) {
  std::vector<CompareCase> out;
  for (const CompareCase& c : cases)
    for (MisWeights w : weights) {
      CompareCase withWeights = c;
      withWeights.weights = w;
      if (w == MisWeights::Optimal) {
        withWeights.label += "-optimal-weights";
        AdaptiveOptions optimal = adaptive;
        optimal.weights = w;
        for (Method m : caseMethods(c, methods)) {
          try {
            for (int budget : budgets) requireValidRun(c.scene, m, Estimator::MultiSample, budget, optimal);
          } catch (const InputError& e) {
            if (!takesOptimalWeights(m, Estimator::MultiSample)) withWeights.leftOut.push_back({m, e.what()});
          }
        }
      }
      out.push_back(withWeights);
    }
  return out;
}

TextTable weightsTable(const Summary& s, int budget) {
  const std::vector<SceneGroup> groups = groupByScene(s);
  TextTable table;
  table.header = {"method", "pdf"};
  for (const SceneGroup& g : groups) table.header.push_back(g.label + ": equal samples / equal time");
  table.header.push_back("geometric means");
  for (Method method : s.methods)
    for (const std::string& pdf : pairedPdfs(groups)) {
      std::vector<TableCell> row{{methodName(method), false}, {pdf, false}};
      double logSamples = 0, logTime = 0;
      int n = 0;
      for (const SceneGroup& g : groups) {
        auto balance = g.byPdf.find(pdf), optimal = g.byPdf.find(pdf + " + optimal weights");
        const MethodSummary* b = balance == g.byPdf.end() ? nullptr : balance->second->find(method);
        const MethodSummary* o = optimal == g.byPdf.end() ? nullptr : optimal->second->find(method);
        const BudgetStats* bb = usable(b) ? b->at(budget) : nullptr;
        const BudgetStats* ob = usable(o) ? o->at(budget) : nullptr;
        if (!bb || !ob) {
          row.push_back({"—", false});
          continue;
        }
        const double samples = bb->mse / ob->mse;
        const CurveValue time = speedUpOver(b->curve(), {ob->wallSeconds, ob->mse});
        row.push_back({fmt::format("{:.2f} / {}", samples, formatCurveValue(time, 2)), false});
        logSamples += std::log(samples);
        logTime += std::log(time.value);
        ++n;
      }
      row.push_back(
          {n > 0 ? fmt::format("{:.2f} / {:.2f}", std::exp(logSamples / n), std::exp(logTime / n)) : "—", false});
      table.rows.push_back(row);
    }
  return table;
}

std::string weightsMarkdown(const Summary& s) {
  if (pairedPdfs(groupByScene(s)).empty()) return "";
  std::string out;
  for (int budget : speedUpBudgets(s))
    out += fmt::format(
        "\n## Optimal weights ([Kon19]) against the balance heuristic, {} spp\n\nEach method with the same counts "
        "and pdf: the balance heuristic's MSE over the optimal weights' at {} spp (equal samples), then how many "
        "times longer the balance heuristic needs to reach the optimal weights' error (equal time; `~`: read past "
        "its measured times). Above 1: the optimal weights win.\n\n{}",
        budget, budget, markdown(weightsTable(s, budget)));
  return out;
}

}  // namespace misalloc
