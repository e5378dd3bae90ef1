#pragma once
// Statistics shared by the distribution tests: Pearson's χ² test with pooling of
// small bins, its p-value through the regularised upper incomplete gamma function,
// and the Šidák correction that keeps a test's false-alarm rate when it makes many
// checks. Every test that compares sample frequencies with a pdf uses these.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace misalloc::test {

// Q(a, x) = Γ(a, x) / Γ(a), the regularised upper incomplete gamma function: the
// series for P below a + 1, Lentz's continued fraction for Q above (Numerical
// Recipes §6.2). The loops stop when terms no longer change a double.
inline double upperRegularisedGamma(double a, double x) {
  constexpr double kDoubleRounding = 0x1p-53;
  if (x <= 0) return 1;
  const double logPrefix = a * std::log(x) - x - std::lgamma(a);
  const double tiny = std::numeric_limits<double>::min();
  if (x < a + 1) {
    double term = 1 / a, sum = term;
    for (int n = 1; term > sum * kDoubleRounding; ++n) {
      term *= x / (a + n);
      sum += term;
    }
    return 1 - sum * std::exp(logPrefix);
  }
  double b = x + 1 - a, c = 1 / tiny, d = 1 / b, h = d;
  for (int i = 1;; ++i) {
    double an = -i * (i - a);
    b += 2;
    d = an * d + b;
    d = std::abs(d) < tiny ? tiny : d;
    c = b + an / c;
    c = std::abs(c) < tiny ? tiny : c;
    d = 1 / d;
    h *= d * c;
    if (std::abs(d * c - 1) <= kDoubleRounding) break;
  }
  return std::exp(logPrefix) * h;
}

struct ChiSquare {
  double statistic = 0;
  int degreesOfFreedom = 0;
  // P(χ² ≥ statistic) for a correct distribution; 1 when nothing was tested.
  double pValue() const {
    return degreesOfFreedom > 0 ? upperRegularisedGamma(0.5 * degreesOfFreedom, 0.5 * statistic) : 1.0;
  }
};

// Pearson's test of observed counts against expected counts (probability × samples).
// Bins expecting fewer than 5 counts, where the χ² approximation fails, are pooled; a
// pool still below 5 joins the smallest regular bin.
inline ChiSquare chiSquareOfExpected(const std::vector<double>& observed, const std::vector<double>& expected) {
  constexpr double kMinExpected = 5;
  std::vector<std::pair<double, double>> bins;  // expected, observed
  double pooledExpected = 0, pooledObserved = 0;
  for (std::size_t i = 0; i < observed.size(); ++i) {
    if (expected[i] >= kMinExpected) {
      bins.emplace_back(expected[i], observed[i]);
    } else {
      pooledExpected += expected[i];
      pooledObserved += observed[i];
    }
  }
  if (pooledExpected >= kMinExpected || bins.empty()) {
    bins.emplace_back(pooledExpected, pooledObserved);
  } else {
    auto smallest = std::min_element(bins.begin(), bins.end());
    smallest->first += pooledExpected;
    smallest->second += pooledObserved;
  }
  ChiSquare result;
  for (const auto& [e, o] : bins) result.statistic += e > 0 ? (o - e) * (o - e) / e : (o > 0 ? HUGE_VAL : 0.0);
  result.degreesOfFreedom = int(bins.size()) - 1;
  return result;
}

// The same for integer counts and bin probabilities, over n samples.
inline ChiSquare chiSquare(const std::vector<uint64_t>& observed, const std::vector<double>& probability, uint64_t n) {
  std::vector<double> o(observed.begin(), observed.end()), e(probability.size());
  for (std::size_t i = 0; i < e.size(); ++i) e[i] = probability[i] * double(n);
  return chiSquareOfExpected(o, e);
}

// Šidák: the level each of `checks` independent checks must pass so that all of them
// together raise a false alarm with probability `familyLevel`.
inline double sidakLevel(double familyLevel, int checks) {
  return -std::expm1(std::log1p(-familyLevel) / checks);
}

// The bound that a standard normal variable's |z| exceeds with probability `level`:
// erfc(z/√2) = level, solved by bisection (erfc falls monotonically).
inline double twoSidedNormalBound(double level) {
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > level ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace misalloc::test
