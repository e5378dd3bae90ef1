#pragma once
// Statistics shared by the distribution tests: Pearson's χ² test with pooling of
// small bins, its p-value through the regularised upper incomplete gamma function,
// and the Šidák correction that keeps a test's false-alarm rate when it makes many
// checks. Every test that compares sample frequencies with a pdf uses these.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
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
inline double sidakLevel(double familyLevel, int checks) { return -std::expm1(std::log1p(-familyLevel) / checks); }

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

// z for a one-sided power of 0.9: a bias of (bound + kPowerZ) standard errors exceeds
// the bound with probability 0.9.
constexpr double kPowerZ = 1.2815515655446004;

// A family of z-tests for bias: each compares an estimate (mean and standard error) with
// what it must equal. The family's false-alarm rate is 1e-3 for up to `maxTests` tests
// (Šidák), and each test states its power: it must detect a relative bias of `detect`
// with probability 0.9, so a test with too few samples fails instead of passing on noise.
// samplesFor sizes a test to just that power.
class BiasFamily {
 public:
  BiasFamily(double detect, int maxTests = 100) : detect_(detect), maxTests_(maxTests) {}

  // The error is floored at 1e-6 of the expected value: a zero-variance estimator (f ∝ p)
  // still rounds each sample's f/(N p) to a float.
  void add(std::string what, double mean, double expected, double standardError) {
    tests_.push_back({std::move(what), mean, expected, std::max(standardError, 1e-6 * std::abs(expected))});
  }

  size_t size() const { return tests_.size(); }
  double bound() const { return twoSidedNormalBound(sidakLevel(1e-3, maxTests_)); }

  // The relative bias a test of this standard error detects with probability 0.9.
  double detectable(double standardError, double expected) const {
    return (bound() + kPowerZ) * standardError / std::abs(expected);
  }
  // The largest over the family: what the family guarantees to find.
  double detectable() const {
    double worst = 0;
    for (const Test& t : tests_) worst = std::max(worst, detectable(t.standardError, t.expected));
    return worst;
  }

  // The samples that give a test its power, from a pilot's standard error with
  // pilotSamples (the error falls as 1/√samples), and a margin of 1.5 for the pilot's own
  // error of its variance.
  long long samplesFor(double pilotStandardError, long long pilotSamples, double expected) const {
    const double ratio = detectable(pilotStandardError, expected) / detect_;
    return (long long)std::ceil(1.5 * double(pilotSamples) * ratio * ratio);
  }

  // One line per test that failed: |z| past the bound (a bias), or a standard error too
  // large to detect the stated bias (too few samples); and one if the family outgrew the
  // bound.
  std::vector<std::string> failures() const {
    const double b = bound();
    std::vector<std::string> out;
    if (tests_.size() > size_t(maxTests_))
      out.push_back(std::to_string(tests_.size()) + " tests, more than the " + std::to_string(maxTests_) +
                    " the bound was set for");
    for (const Test& t : tests_) {
      const double z = (t.mean - t.expected) / t.standardError;
      const double d = detectable(t.standardError, t.expected);
      const std::string numbers = t.what + ": mean " + std::to_string(t.mean) + " expected " +
                                  std::to_string(t.expected) + " z " + std::to_string(z) + " (bound " +
                                  std::to_string(b) + "), detects a bias of " + std::to_string(100 * d) + " %";
      if (!(std::abs(z) < b)) out.push_back("biased: " + numbers);
      if (!(d <= detect_))
        out.push_back("too few samples to detect " + std::to_string(100 * detect_) + " %: " + numbers);
    }
    return out;
  }

 private:
  struct Test {
    std::string what;
    double mean, expected, standardError;
  };
  double detect_;
  int maxTests_;
  std::vector<Test> tests_;
};

}  // namespace misalloc::test
