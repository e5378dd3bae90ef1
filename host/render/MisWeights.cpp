#include "render/MisWeights.h"

#include <fmt/format.h>

#include "Error.h"

namespace misalloc {

MisWeights parseMisWeights(const std::string& name, const std::string& option) {
  if (name == "balance") return MisWeights::Balance;
  if (name == "optimal") return MisWeights::Optimal;
  throw InputError(fmt::format("{} '{}': expected balance (the balance heuristic) or optimal ([Kon19])", option, name));
}

std::string misWeightsName(MisWeights weights) { return weights == MisWeights::Optimal ? "optimal" : "balance"; }

}  // namespace misalloc
