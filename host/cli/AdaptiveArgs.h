#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "render/Render.h"

namespace misalloc {

// The options of the adaptive methods (and of oracle and ris), shared by render and compare.
struct AdaptiveArgs {
  AdaptiveOptions options;
  std::string costList = "cached", linearRule = "variance", gridRule = "variance";

  void add(CLI::App& command);

  // The options with the rules parsed and the costs, when given, checked for M
  // techniques; throws InputError.
  AdaptiveOptions make(int techniqueCount) const;
};

}  // namespace misalloc
