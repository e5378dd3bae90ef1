#include "compare/Summary.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace misalloc {
namespace {

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Errors are averaged; times take the median, which a render slowed by another
// process on a shared machine does not move.
BudgetStats reduceRepeats(const std::vector<const RunRecord*>& runs) {
  BudgetStats s;
  s.budget = runs.front()->budget;
  s.repeats = int(runs.size());
  s.meanAlpha.assign(runs.front()->meanAlpha.size(), 0.0);
  std::vector<double> wall, kernel, allocation, host;
  double sumRmse = 0, sumRmse2 = 0;
  for (const RunRecord* r : runs) {
    s.mse += r->mse;
    s.relativeMse += r->relativeMse;
    wall.push_back(r->wallSeconds);
    kernel.push_back(r->kernelSeconds);
    allocation.push_back(r->allocationSeconds);
    host.push_back(r->hostSeconds);
    for (size_t k = 0; k < s.meanAlpha.size(); ++k) s.meanAlpha[k] += r->meanAlpha[k];
    double rmse = 1000 * std::sqrt(std::max(0.0, r->mse));
    sumRmse += rmse;
    sumRmse2 += rmse * rmse;
  }
  const double n = s.repeats;
  s.mse /= n;
  s.relativeMse /= n;
  for (double& a : s.meanAlpha) a /= n;
  s.wallSeconds = median(wall);
  s.kernelSeconds = median(kernel);
  s.allocationSeconds = median(allocation);
  s.hostSeconds = median(host);
  s.rmseX1000 = 1000 * std::sqrt(std::max(0.0, s.mse));
  s.rmseSpreadX1000 = n > 1 ? std::sqrt(std::max(0.0, (sumRmse2 - sumRmse * sumRmse / n) / (n - 1))) : 0;
  s.efficiency = 1 / (s.mse * s.wallSeconds);
  return s;
}

MethodSummary summarizeMethod(const Comparison& comparison, const std::string& caseLabel, Method method,
                              const std::vector<int>& budgets, int repeats) {
  MethodSummary m{method, {}, {}, {}};
  for (int budget : budgets) {
    std::vector<const RunRecord*> runs;
    for (const RunRecord& r : comparison.runs)
      if (r.caseLabel == caseLabel && r.method == method && r.budget == budget) runs.push_back(&r);
    if (int(runs.size()) == repeats) m.budgets.push_back(reduceRepeats(runs));
  }
  return m;
}

bool usableCurve(const MethodSummary& m) {
  return !m.budgets.empty() && std::all_of(m.budgets.begin(), m.budgets.end(), [](const BudgetStats& b) {
    return b.mse > 0 && std::isfinite(b.mse) && b.wallSeconds > 0;
  });
}

void compareAtEqualTime(CaseSummary& c) {
  const MethodSummary* equal = c.find(Method::Equal);
  if (equal && !usableCurve(*equal)) equal = nullptr;
  const MethodSummary* timeBase = equal;
  for (auto m = c.methods.begin(); !timeBase && m != c.methods.end(); ++m)
    if (usableCurve(*m)) timeBase = &*m;
  if (timeBase)
    for (const BudgetStats& b : timeBase->budgets) c.commonSeconds.push_back(b.wallSeconds);
  std::optional<ErrorCurve> equalCurve;
  if (equal) equalCurve = equal->curve();
  for (MethodSummary& m : c.methods) {
    if (!usableCurve(m)) continue;
    ErrorCurve curve = m.curve();
    m.slope = curve.logLogSlope();
    for (double t : c.commonSeconds) {
      CurveValue mse = curve.mseAt(t);
      m.equalTimeRmseX1000.push_back({1000 * std::sqrt(mse.value), mse.extrapolated});
    }
    if (!equalCurve) continue;
    for (BudgetStats& b : m.budgets) b.speedUp = speedUpOver(*equalCurve, {b.wallSeconds, b.mse});
  }
}

std::optional<CostModelAccuracy> costModelAccuracy(const std::vector<RunRecord>& runs) {
  std::vector<double> errors;
  for (const RunRecord& r : runs)
    for (const StageTiming& t : r.stages)
      if (t.predictedKernelSeconds) errors.push_back(std::abs(*t.predictedKernelSeconds / t.kernelSeconds - 1));
  if (errors.empty()) return std::nullopt;
  return CostModelAccuracy{int(errors.size()), median(errors), *std::max_element(errors.begin(), errors.end())};
}

}  // namespace

ErrorCurve MethodSummary::curve() const {
  std::vector<CurvePoint> points;
  for (const BudgetStats& b : budgets) points.push_back({b.wallSeconds, b.mse});
  return ErrorCurve(points);
}

const BudgetStats* MethodSummary::at(int budget) const {
  for (const BudgetStats& b : budgets)
    if (b.budget == budget) return &b;
  return nullptr;
}

const MethodSummary* CaseSummary::find(Method method) const {
  for (const MethodSummary& m : methods)
    if (m.method == method) return &m;
  return nullptr;
}

Summary summarize(const Comparison& comparison, const CompareOptions& options) {
  Summary s;
  s.methods = options.methods;
  s.budgets = options.budgets;
  s.interrupted = comparison.interrupted;
  s.costModel = costModelAccuracy(comparison.runs);
  s.tableBudget = *std::min_element(options.budgets.begin(), options.budgets.end(), [&](int a, int b) {
    return std::abs(a - options.tableBudget) < std::abs(b - options.tableBudget);
  });
  for (const CaseInfo& info : comparison.cases) {
    CaseSummary c{info, {}, {}};
    for (Method method : options.methods)
      c.methods.push_back(summarizeMethod(comparison, info.label, method, options.budgets, options.repeats));
    compareAtEqualTime(c);
    s.cases.push_back(std::move(c));
  }
  return s;
}

}  // namespace misalloc
