#include "distributions/AliasTable.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace misalloc {

namespace {

// Vose's construction on q, which holds the weights on entry.
void buildInto(std::vector<double>& q, float* probability, uint32_t* alias, std::vector<uint32_t>& under,
               std::vector<uint32_t>& over) {
  const std::size_t n = q.size();
  if (n == 0 || n > std::numeric_limits<uint32_t>::max())
    throw std::invalid_argument("an alias table needs between 1 and 2^32 - 1 weights");
  double total = 0;
  for (double w : q) {
    if (!(w >= 0) || !std::isfinite(w)) throw std::invalid_argument("alias table weights must be finite and >= 0");
    total += w;
  }
  if (!(total > 0) || !std::isfinite(total))
    throw std::invalid_argument("alias table weights must have a finite, positive sum");

  // q_i = N p_i: bucket i keeps q_i of its unit of mass and lends the rest to its alias.
  // w / total ≤ 1 cannot overflow, whatever the weights' scale.
  for (double& w : q) w = w / total * double(n);

  // Buckets of weight 0 go on top of the `under` stack so they are paired first, while
  // `over` still holds a surplus of at least one unit per remaining zero. Pairing a
  // zero, q_l − 1, is exact in double; until the zeros run out the only rounding comes
  // from the at most one positive pairing per large bucket, far below a unit. So
  // every zero gets probability 0 and a positive alias instead of being left over.
  under.clear();
  over.clear();
  for (uint32_t i = 0; i < n; ++i) (q[i] < 1 ? under : over).push_back(i);
  std::partition(under.begin(), under.end(), [&q](uint32_t i) { return q[i] > 0; });

  while (!under.empty() && !over.empty()) {
    uint32_t small = under.back(), large = over.back();
    under.pop_back();
    probability[small] = float(q[small]);
    alias[small] = large;
    // (q_l + q_s) − 1 rounds once on the sum instead of on 1 − q_s as well.
    q[large] = (q[large] + q[small]) - 1;
    if (q[large] < 1) {
      over.pop_back();
      under.push_back(large);
    }
  }
  // What is left has q = 1 up to rounding: accept always.
  for (const auto* rest : {&under, &over}) {
    for (uint32_t i : *rest) {
      probability[i] = 1;
      alias[i] = i;
    }
  }
}

}  // namespace

AliasTable buildAliasTable(std::vector<double> weights) {
  AliasTable table{std::vector<float>(weights.size()), std::vector<uint32_t>(weights.size())};
  std::vector<uint32_t> under, over;
  buildInto(weights, table.probability.data(), table.alias.data(), under, over);
  return table;
}

void buildAliasTable(const double* weights, std::size_t n, float* probability, uint32_t* alias, AliasScratch& scratch) {
  scratch.q.assign(weights, weights + n);
  buildInto(scratch.q, probability, alias, scratch.under, scratch.over);
}

}  // namespace misalloc
