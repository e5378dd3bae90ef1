#pragma once
#include <optional>
#include <vector>

#include "compare/Comparison.h"
#include "compare/ErrorCurve.h"

namespace misalloc {

// The repeats of one (case, method, budget), reduced.
struct BudgetStats {
  int budget = 0;
  int repeats = 0;
  double mse = 0;              // mean over repeats
  double rmseX1000 = 0;        // 1000 √(mean MSE)
  double rmseSpreadX1000 = 0;  // sample standard deviation of the repeats' RMSE × 1000
  double relativeMse = 0;      // mean
  double wallSeconds = 0, kernelSeconds = 0, allocationSeconds = 0, hostSeconds = 0;  // medians
  double efficiency = 0;                                                              // 1/(mean MSE × median time)
  std::vector<double> meanAlpha;
  std::optional<CurveValue> speedUp;  // over equal at this error (speedUpOver); none without equal
};

struct MethodSummary {
  Method method;
  std::vector<BudgetStats> budgets;            // ascending
  std::optional<double> slope;                 // log MSE against log t (−1: Monte Carlo)
  std::vector<CurveValue> equalTimeRmseX1000;  // at CaseSummary::commonSeconds

  ErrorCurve curve() const;
  const BudgetStats* at(int budget) const;
};

struct CaseSummary {
  CaseInfo info;
  std::vector<MethodSummary> methods;
  // The common time budgets of the equal-time comparison: equal's median times at its
  // budgets (the first method's when equal was not run).
  std::vector<double> commonSeconds;

  const MethodSummary* find(Method method) const;
};

// How well the cost model (sampling/CostModel.h) predicted the kernel time of the
// adaptive renders' stages: |predicted/measured − 1|, over every such stage.
struct CostModelAccuracy {
  int stages = 0;
  double median = 0, worst = 0;
};

struct Summary {
  std::vector<CaseSummary> cases;
  std::optional<CostModelAccuracy> costModel;  // none without an adaptive render
  std::vector<Method> methods;
  std::vector<int> budgets;
  int tableBudget = 0;  // the budget nearest to CompareOptions::tableBudget
  bool interrupted = false;
};

// Means and spreads over repeats, error-vs-time curves, the equal-time errors and the
// speed-ups over equal. Budgets that not every repeat finished are left out.
Summary summarize(const Comparison& comparison, const CompareOptions& options);

}  // namespace misalloc
