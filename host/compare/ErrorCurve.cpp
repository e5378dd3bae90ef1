#include "compare/ErrorCurve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace misalloc {

ErrorCurve::ErrorCurve(std::vector<CurvePoint> points) : points_(std::move(points)) {
  if (points_.empty()) throw std::invalid_argument("ErrorCurve: no points");
  for (const CurvePoint& p : points_)
    if (!(p.seconds > 0 && p.mse > 0 && std::isfinite(p.seconds) && std::isfinite(p.mse)))
      throw std::invalid_argument("ErrorCurve: times and errors must be positive and finite");
  std::stable_sort(points_.begin(), points_.end(),
                   [](const CurvePoint& a, const CurvePoint& b) { return a.seconds < b.seconds; });
}

CurveValue ErrorCurve::mseAt(double seconds) const {
  const CurvePoint &first = points_.front(), &last = points_.back();
  if (seconds < first.seconds) return {first.mse * first.seconds / seconds, true};
  if (seconds > last.seconds) return {last.mse * last.seconds / seconds, true};
  for (size_t i = 0; i + 1 < points_.size(); ++i) {
    const CurvePoint &a = points_[i], &b = points_[i + 1];
    if (seconds > b.seconds) continue;
    if (b.seconds == a.seconds) return {a.mse, false};
    double s = std::log(seconds / a.seconds) / std::log(b.seconds / a.seconds);
    return {a.mse * std::pow(b.mse / a.mse, s), false};
  }
  return {last.mse, false};  // seconds == last.seconds
}

CurveValue ErrorCurve::secondsFor(double mse) const {
  const CurvePoint &first = points_.front(), &last = points_.back();
  // Noise can make the curve rise between budgets: take its first crossing.
  for (size_t i = 0; i + 1 < points_.size(); ++i) {
    const CurvePoint &a = points_[i], &b = points_[i + 1];
    if ((mse - a.mse) * (mse - b.mse) > 0) continue;
    if (a.mse == b.mse) return {a.seconds, false};
    double s = std::log(mse / a.mse) / std::log(b.mse / a.mse);
    return {a.seconds * std::pow(b.seconds / a.seconds, s), false};
  }
  if (points_.size() == 1 && mse == first.mse) return {first.seconds, false};
  // Outside the measured errors: continue the end that lies nearer in error.
  const CurvePoint& end = std::abs(std::log(mse / first.mse)) < std::abs(std::log(mse / last.mse)) ? first : last;
  return {end.seconds * end.mse / mse, true};
}

std::optional<double> ErrorCurve::logLogSlope() const {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const CurvePoint& p : points_) {
    double x = std::log(p.seconds), y = std::log(p.mse);
    n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  double denominator = n * sxx - sx * sx;
  if (n < 2 || !(denominator > 1e-12 * n * n)) return std::nullopt;
  return (n * sxy - sx * sy) / denominator;
}

CurveValue speedUpOver(const ErrorCurve& equal, const CurvePoint& point) {
  CurveValue t = equal.secondsFor(point.mse);
  return {t.value / point.seconds, t.extrapolated};
}

}  // namespace misalloc
