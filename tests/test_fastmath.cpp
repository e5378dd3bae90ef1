// The kernels' inlinable maths (kernels/fastmath.h) against the C++ standard library
// in double. The bounds are a few float ulps of the results: what float arithmetic
// itself can give, so the approximations add no error of their own beyond it.
#include <catch2/catch.hpp>
#include <cmath>

#include "KernelCode.h"

using namespace misalloc::kern;

namespace {
constexpr double kUlp = 1.0 / (1 << 23);  // float's relative spacing at 1
}

TEST_CASE("fastLog2 and fastExp2 are accurate to a few ulps", "[fastmath]") {
  double worstLog = 0, worstExp = 0;
  for (double x = 1e-30; x < 1e30; x *= 1.0137) {
    double err = std::abs(fastLog2(float(x)) - std::log2(double(float(x))));
    worstLog = std::max(worstLog, err / std::max(1.0, std::abs(std::log2(x))));
  }
  for (double y = -120; y < 120; y += 0.0137) {
    double exact = std::exp2(double(float(y)));
    worstExp = std::max(worstExp, std::abs(fastExp2(float(y)) - exact) / exact);
  }
  CHECK(worstLog < 4 * kUlp);
  CHECK(worstExp < 4 * kUlp);
  CHECK(fastExp2(-200.0f) == 0.0f);
}

TEST_CASE("fastPow matches pow for the Phong lobe's range", "[fastmath]") {
  // Relative error of x^n is about |n log x| times the error of the logarithm.
  double worst = 0;
  for (double n : {0.1, 1.0, 5.0, 37.3, 100.0, 1000.0}) {
    for (double x = 1e-3; x <= 1.0; x += 1e-3) {
      double exact = std::pow(double(float(x)), double(float(n)));
      if (exact < 1e-30) continue;
      double err = std::abs(fastPow(float(x), float(n)) - exact) / exact;
      worst = std::max(worst, err / (std::max(1.0, std::abs(n * std::log(x)))));
    }
  }
  CHECK(worst < 8 * kUlp);
  CHECK(fastPow(0.0f, 3.0f) == 0.0f);
  CHECK(fastPow(-0.5f, 3.0f) == 0.0f);
}

TEST_CASE("sinCos2Pi, fastAcos and fastAtan2Positive", "[fastmath]") {
  double worstSin = 0, worstAcos = 0, worstAtan = 0;
  for (double u = 0; u <= 1.0; u += 1.0 / 7919) {
    MaSinCos sc = sinCos2Pi(float(u));
    double phi = 2 * M_PI * double(float(u));
    worstSin = std::max({worstSin, std::abs(sc.s - std::sin(phi)), std::abs(sc.c - std::cos(phi))});
    float x = float(std::cos(phi)), y = float(std::sin(phi));
    double exact = std::atan2(double(y), double(x));
    if (exact < 0) exact += 2 * M_PI;
    double err = std::abs(fastAtan2Positive(y, x) - exact);
    worstAtan = std::max(worstAtan, std::min(err, 2 * M_PI - err));
  }
  for (double z = -1; z <= 1; z += 1.0 / 7919)
    worstAcos = std::max(worstAcos, std::abs(fastAcos(float(z)) - std::acos(double(float(z)))));
  CHECK(worstSin < 4 * kUlp);
  CHECK(worstAtan < 8 * kUlp * M_PI);
  CHECK(worstAcos < 8 * kUlp * M_PI);
}
