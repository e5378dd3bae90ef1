#pragma once
#include <string>
#include <vector>

#include "compare/Comparison.h"

namespace misalloc {

// `compare --suite`: every shipped envmap × the seed000 grid with the alias sampler,
// plus the default map with the binary-search (CDF) sampler, whose measured cost
// ratio is the one where the cost-aware allocations matter ([HS14] Sec. 5.2: c_BRDF =
// 0.21 c_EM with a binary search).
std::vector<CompareCase> suiteCases(int width, int height);

// A column label for a scene: the envmap's name (file name without .exr, or the
// procedural spec), "-cdf" with the binary-search sampler, "-split" for M = 3,
// "-compC" with the compensated envmap pdf of envmap fraction C ([Kar19]); only
// letters, digits, '.', '_' and '-', so that it also names a folder.
std::string caseLabel(const SceneOptions& scene);

}  // namespace misalloc
