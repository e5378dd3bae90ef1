#pragma once
#include <string>

#include "compare/EnvmapPdfComparison.h"

namespace misalloc {

// A log–log SVG of one scene with every pdf it ran: RMSE×1000 against wall-clock time
// per render, one line per method and pdf through its budgets (the colour the method's,
// the dash the pdf's), with bars of ± the spread over repeats. A method with a constant
// efficiency 1/(MSE·t) is a line of slope −1/2; lower is better.
std::string errorTimePlotSvg(const SceneGroup& scene);

}  // namespace misalloc
