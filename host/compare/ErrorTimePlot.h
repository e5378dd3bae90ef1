#pragma once
#include <string>

#include "compare/Summary.h"

namespace misalloc {

// A log–log SVG of one scene: RMSE×1000 against wall-clock time per render, one line
// per method through its budgets, with bars of ± the spread over repeats. A method
// with a constant efficiency 1/(MSE·t) is a line of slope −1/2; lower is better.
std::string errorTimePlotSvg(const CaseSummary& scene);

}  // namespace misalloc
