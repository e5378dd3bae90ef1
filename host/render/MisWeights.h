#pragma once
// Which MIS weights a render's multi-sample stages use (--weights).
#include <string>

namespace misalloc {

enum class MisWeights {
  Balance,  // the balance heuristic ([HS14] eq. 4.1–4.3)
  Optimal,  // [Kon19]'s optimal weights, solved per pixel from the stages before (alloc/OptimalWeights.h)
};

// Throws InputError naming `option` for anything but "balance" or "optimal".
MisWeights parseMisWeights(const std::string& name, const std::string& option);
std::string misWeightsName(MisWeights weights);

}  // namespace misalloc
