#pragma once
#include <optional>
#include <vector>

namespace misalloc {

// One method's mean error at each of its budgets, against its median wall time.
struct CurvePoint {
  double seconds = 0;
  double mse = 0;
};

// A value read off an error-vs-time curve, and whether it lies outside the measured
// range (then it continues the nearest end with the Monte Carlo law MSE ∝ 1/t).
struct CurveValue {
  double value = 0;
  bool extrapolated = false;
};

// Piecewise linear in log t – log MSE through the points, sorted by time. Monte Carlo
// error falls as 1/t at a fixed allocation, so outside the measured times each end
// is continued with slope −1 rather than with the end segment's noisy slope.
class ErrorCurve {
 public:
  // Throws std::invalid_argument for no points or a non-positive time or MSE.
  explicit ErrorCurve(std::vector<CurvePoint> points);

  // The MSE the method reaches in `seconds`: the equal-time comparison.
  CurveValue mseAt(double seconds) const;
  // The time the method needs to reach `mse`: the first crossing along the curve.
  CurveValue secondsFor(double mse) const;
  // Least-squares slope of log MSE against log t over the points (−1: the Monte Carlo
  // rate); empty for fewer than two distinct times.
  std::optional<double> logLogSlope() const;

  const std::vector<CurvePoint>& points() const { return points_; }

 private:
  std::vector<CurvePoint> points_;
};

// t_equal(e) / t: how much longer equal-count MIS takes to reach the error `point`
// reaches, i.e. the speed-up of `point`'s method over `equal` at equal error.
CurveValue speedUpOver(const ErrorCurve& equal, const CurvePoint& point);

}  // namespace misalloc
