#include "alloc/Apportion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace misalloc {

namespace {

double validatedSum(const double* alpha, int m) {
  double sum = 0;
  for (int k = 0; k < m; ++k) {
    if (!(std::isfinite(alpha[k]) && alpha[k] >= 0))
      throw std::invalid_argument("apportionCounts: weights must be finite and >= 0");
    sum += alpha[k];
  }
  if (sum == 0) throw std::invalid_argument("apportionCounts: weights sum to 0");
  return sum;
}

}  // namespace

void apportionCounts(const double* alpha, int m, int total, int* counts) {
  if (total < 0) throw std::invalid_argument("apportionCounts: negative total " + std::to_string(total));
  const double sum = validatedSum(alpha, m);
  auto quota = [&](int k) { return alpha[k] / sum * total; };
  int assigned = 0;
  for (int k = 0; k < m; ++k) {
    counts[k] = std::min(static_cast<int>(std::floor(quota(k))), total - assigned);
    assigned += counts[k];
  }
  // Σ ⌊quota⌋ > N − m, so fewer than m techniques receive one more sample: each to the
  // largest remainder not yet served, ties to the lower index.
  unsigned served = 0;
  for (; assigned < total; ++assigned) {
    int next = -1;
    double largest = -1;
    for (int k = 0; k < m; ++k) {
      double remainder = quota(k) - counts[k];
      if (!(served >> k & 1u) && remainder > largest) largest = remainder, next = k;
    }
    served |= 1u << next;
    ++counts[next];
  }
}

std::vector<int> apportionCounts(const std::vector<double>& alpha, int total) {
  std::vector<int> counts(alpha.size());
  apportionCounts(alpha.data(), int(alpha.size()), total, counts.data());
  return counts;
}

bool floorCounts(int* counts, int m) {
  bool changed = false;
  for (int k = 0; k < m; ++k) {
    if (counts[k] > 0) continue;
    int* largest = std::max_element(counts, counts + m);
    if (*largest <= 1) break;
    --*largest;
    counts[k] = 1;
    changed = true;
  }
  return changed;
}

}  // namespace misalloc
