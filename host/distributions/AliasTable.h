#pragma once
// Vose's alias method (Vose 1991; pbrt-v4 AliasTable): O(1) sampling of a discrete
// distribution from one uniform bucket and one coin flip.
#include <cstdint>
#include <vector>

namespace misalloc {

// Bucket i is returned with probability (probability[i] + Σ_{j: alias[j] = i}
// (1 − probability[j])) / N, which is weight i / Σ weights. The layout is what
// kernels/envmap.h's sampleAliasTable reads.
struct AliasTable {
  std::vector<float> probability;  // accept bucket i when the coin is below this
  std::vector<uint32_t> alias;     // else return alias[i]
};

// From N ≥ 1 finite, non-negative weights with a positive sum (else throws
// std::invalid_argument), computed in double. A bucket of weight 0 is never
// returned: its probability is 0 and its alias has a positive weight. Taken by
// value: the table reuses the weights' memory, so callers with large maps move them in.
AliasTable buildAliasTable(std::vector<double> weights);

// The same for many small tables: weights[0, n) into probability[0, n) and alias[0, n),
// with the working memory kept in `scratch` from one call to the next.
struct AliasScratch {
  std::vector<double> q;
  std::vector<uint32_t> under, over;
};
void buildAliasTable(const double* weights, std::size_t n, float* probability, uint32_t* alias, AliasScratch& scratch);

}  // namespace misalloc
