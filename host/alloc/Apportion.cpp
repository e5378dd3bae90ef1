#include "alloc/Apportion.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

namespace misalloc {

namespace {

double validatedSum(const std::vector<double>& alpha) {
  double sum = 0;
  for (double a : alpha) {
    if (!(std::isfinite(a) && a >= 0)) throw std::invalid_argument("apportionCounts: weights must be finite and >= 0");
    sum += a;
  }
  if (sum == 0) throw std::invalid_argument("apportionCounts: weights sum to 0");
  return sum;
}

}  // namespace

std::vector<int> apportionCounts(const std::vector<double>& alpha, int total) {
  if (total < 0) throw std::invalid_argument("apportionCounts: negative total " + std::to_string(total));
  double sum = validatedSum(alpha);
  std::size_t m = alpha.size();
  std::vector<int> counts(m);
  std::vector<double> remainder(m);
  int assigned = 0;
  for (std::size_t k = 0; k < m; ++k) {
    double quota = alpha[k] / sum * total;
    counts[k] = std::min(static_cast<int>(std::floor(quota)), total - assigned);
    remainder[k] = quota - counts[k];
    assigned += counts[k];
  }
  std::vector<std::size_t> order(m);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return remainder[a] > remainder[b]; });
  // Σ ⌊quota⌋ > N − m, so fewer than m techniques receive one more sample.
  for (std::size_t r = 0; assigned < total; ++r, ++assigned) ++counts[order[r]];
  return counts;
}

}  // namespace misalloc
