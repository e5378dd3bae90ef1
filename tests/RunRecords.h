#pragma once
// A RunRecord of compare with just what the summary tables read, for tests that
// build comparisons by hand.
#include <string>

#include "compare/Comparison.h"

namespace misalloc::test {

inline RunRecord record(const std::string& label, Method m, int budget, int repeat, double seconds, double mse) {
  RunRecord r;
  r.caseLabel = label;
  r.method = m;
  r.budget = budget;
  r.repeat = repeat;
  r.wallSeconds = r.kernelSeconds = seconds;
  r.mse = mse;
  r.meanAlpha = {0.5, 0.5};
  return r;
}

}  // namespace misalloc::test
