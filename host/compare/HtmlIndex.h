#pragma once
#include <string>

#include "compare/Summary.h"

namespace misalloc {

// One self-contained page for a comparison's output folder, viewable offline: the
// summary tables, and per scene the error-vs-time plot of every method and pdf, then
// per pdf the equal-time table, the reference and every method's repeat-0 image per
// budget with its α map. It links only files of the folder (plot_<scene>.svg,
// <case>/*.png), by relative paths.
std::string indexHtml(const Summary& summary);

// The file name of a scene's plot in the output folder: that of its first case.
std::string plotFileName(const std::string& sceneLabel);

}  // namespace misalloc
