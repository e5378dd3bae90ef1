#include "paper/MixtureOptimizer.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>

#include "alloc/Allocation.h"

namespace misalloc {

namespace {

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  return std::inner_product(a.begin(), a.end(), b.begin(), 0.0);
}

// Euclidean projection onto the probability simplex (sort-based; Held, Wolfe & Crowder 1974).
std::vector<double> projectToSimplex(std::vector<double> v) {
  std::vector<double> sorted = v;
  std::sort(sorted.begin(), sorted.end(), std::greater<>());
  double cumulative = 0, shift = 0;
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    cumulative += sorted[i];
    double candidate = (cumulative - 1) / static_cast<double>(i + 1);
    if (sorted[i] > candidate) shift = candidate;
  }
  for (double& x : v) x = std::max(x - shift, 0.0);
  return v;
}

// A linear constraint a·α ≥ b on the mixture weights.
struct HalfSpace {
  std::vector<double> a;
  double b;
};

// The exact Euclidean projection of v onto {α : Σ α = 1, a_j·α ≥ b_j}: the projection
// onto the affine set where Σ α = 1 and some set S of the constraints holds with
// equality, for every S of at most M − 1 constraints; the nearest of the feasible ones
// is the projection, since the projection itself is among them.
std::vector<double> projectToPolytope(const std::vector<double>& v, const std::vector<HalfSpace>& constraints) {
  // Round-off of the affine projections for |v| ≲ 10; below the validity margin.
  constexpr double kSlack = 1e-13;
  int m = static_cast<int>(v.size()), n = static_cast<int>(constraints.size());
  Eigen::Map<const Eigen::VectorXd> point(v.data(), m);
  std::vector<double> best;
  double bestDistance = std::numeric_limits<double>::infinity();
  std::vector<int> active;
  std::function<void(int)> visit = [&](int first) {
    Eigen::MatrixXd c(active.size() + 1, m);
    Eigen::VectorXd d(active.size() + 1);
    c.row(0).setOnes();
    d(0) = 1;
    for (std::size_t r = 0; r < active.size(); ++r) {
      c.row(r + 1) = Eigen::Map<const Eigen::RowVectorXd>(constraints[active[r]].a.data(), m);
      d(r + 1) = constraints[active[r]].b;
    }
    Eigen::FullPivLU<Eigen::MatrixXd> lu(c * c.transpose());
    if (lu.isInvertible()) {
      Eigen::VectorXd x = point + c.transpose() * lu.solve(d - c * point);
      bool feasible = true;
      for (const HalfSpace& h : constraints)
        feasible = feasible && Eigen::Map<const Eigen::VectorXd>(h.a.data(), m).dot(x) >= h.b - kSlack;
      if (feasible && (x - point).squaredNorm() < bestDistance) {
        bestDistance = (x - point).squaredNorm();
        best.assign(x.data(), x.data() + m);
      }
    }
    if (static_cast<int>(active.size()) == m - 1) return;
    for (int j = first; j < n; ++j) {
      active.push_back(j);
      visit(j + 1);
      active.pop_back();
    }
  };
  visit(0);
  // The caller's current point is valid, so the polytope is not empty.
  if (best.empty()) throw std::logic_error("projectToPolytope: no feasible point");
  for (double& x : best) x = std::max(x, 0.0);
  double sum = std::accumulate(best.begin(), best.end(), 0.0);
  for (double& x : best) x /= sum;
  return best;
}

// Projection onto the valid mixtures {α in the simplex : p_α ≥ 0 at every probe}, a
// convex polytope. Probe constraints are added as they are found violated, with a
// margin of 1e-12 so that the projection is strictly valid.
class ValidMixtureProjection {
 public:
  explicit ValidMixtureProjection(const Example1D& example) : example_(example) {
    int m = example.techniqueCount();
    for (int k = 0; k < m; ++k) {
      constraints_.push_back({std::vector<double>(m, 0.0), 0.0});
      constraints_.back().a[k] = 1;
    }
  }

  std::vector<double> operator()(const std::vector<double>& v) {
    constexpr std::size_t kMaxProbeConstraints = 8;
    constexpr double kMargin = 1e-12;
    for (;;) {
      std::vector<double> x =
          constraints_.size() == v.size() ? projectToSimplex(v) : projectToPolytope(v, constraints_);
      std::optional<std::vector<double>> probe = example_.mostViolatedProbe(x);
      if (!probe || constraints_.size() == v.size() + kMaxProbeConstraints) return x;
      constraints_.push_back({*probe, kMargin});
    }
  }

 private:
  const Example1D& example_;
  std::vector<HalfSpace> constraints_;  // α_k ≥ 0, then the probes
};

struct Evaluation {
  bool valid = false;
  double variance = 0, inefficiency = 0;
  std::vector<double> gradient;
};

Evaluation evaluate(const Example1D& example, VarianceModel model, const std::vector<double>& costs,
                    const std::vector<double>& alpha) {
  bool multi = model == VarianceModel::MultiSample;
  MixtureMoments moments = mixtureMoments(example, alpha, multi);
  if (moments.status != VarianceStatus::Finite) return {};
  int m = example.techniqueCount();
  double v = multi ? multiSampleVariance(moments, alpha).value : oneSampleVariance(moments, example.integral()).value;
  double cost = dot(costs, alpha);
  Evaluation e{true, v, inefficiency(costs, alpha, v), std::vector<double>(m)};
  for (int j = 0; j < m; ++j) {
    double dv = -moments.techniqueSecondMoment[j];
    if (multi) {
      dv -= moments.techniqueMean[j] * moments.techniqueMean[j];
      for (int i = 0; i < m; ++i) dv += 2 * alpha[i] * moments.techniqueMean[i] * moments.crossMoment[i * m + j];
    }
    e.gradient[j] = costs[j] * v + cost * dv;
  }
  return e;
}

}  // namespace

VarianceValue mixtureVariance(const Example1D& example, VarianceModel model, const std::vector<double>& alpha) {
  return model == VarianceModel::OneSample ? oneSampleVariance(example, alpha) : multiSampleVariance(example, alpha);
}

OptimalMixture minimiseInefficiency(const Example1D& example, VarianceModel model, const std::vector<double>& costs) {
  int m = example.techniqueCount();
  validateCosts(costs, m);
  constexpr int kMaxIterations = 2000, kMemory = 10;
  constexpr double kArmijo = 1e-4, kStationarity = 1e-12, kMinStep = 1e-30;

  std::vector<double> x(m, 1.0 / m);
  Evaluation e = evaluate(example, model, costs, x);
  if (!e.valid)
    throw std::domain_error("minimiseInefficiency: equal weights are not a valid mixture for example " + example.id());
  std::deque<double> history{e.inefficiency};
  ValidMixtureProjection project(example);
  double spectralStep = 1;
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    // The simplex has diameter √2, so steps are capped at 10/‖g‖∞ and stationarity is
    // measured with the gradient scaled likewise; this keeps the projected points
    // O(1), where the projection is accurate.
    double gradientNorm = 0;
    for (double g : e.gradient) gradientNorm = std::max(gradientNorm, std::abs(g));
    std::vector<double> trial(m), d(m);
    for (int k = 0; k < m; ++k) trial[k] = x[k] - e.gradient[k] / std::max(1.0, gradientNorm);
    std::vector<double> unitStep = project(trial);
    double stationarity = 0;
    for (int k = 0; k < m; ++k) stationarity = std::max(stationarity, std::abs(unitStep[k] - x[k]));
    if (stationarity <= kStationarity) return {x, e.variance, e.inefficiency, true};

    double step = std::min(spectralStep, 10 / std::max(gradientNorm, 1e-300));
    for (int k = 0; k < m; ++k) trial[k] = x[k] - step * e.gradient[k];
    std::vector<double> target = project(trial);
    for (int k = 0; k < m; ++k) d[k] = target[k] - x[k];
    double reference = *std::max_element(history.begin(), history.end());
    double slope = dot(e.gradient, d);
    // Backtracking; a mixture with infinite variance counts as +∞.
    Evaluation next;
    std::vector<double> xNext(m);
    for (double t = 1;; t *= 0.5) {
      if (t < kMinStep) return {x, e.variance, e.inefficiency, false};
      for (int k = 0; k < m; ++k) xNext[k] = x[k] + t * d[k];
      next = evaluate(example, model, costs, xNext);
      if (next.valid && next.inefficiency <= reference + kArmijo * t * slope) break;
    }
    std::vector<double> s(m), y(m);
    for (int k = 0; k < m; ++k) {
      s[k] = xNext[k] - x[k];
      y[k] = next.gradient[k] - e.gradient[k];
    }
    double sy = dot(s, y);
    spectralStep = sy > 0 ? std::clamp(dot(s, s) / sy, 1e-10, 1e10) : 1e10;
    x = xNext;
    e = next;
    history.push_back(e.inefficiency);
    if (static_cast<int>(history.size()) > kMemory) history.pop_front();
  }
  return {x, e.variance, e.inefficiency, false};
}

GridMinimum gridMinimum(const Example1D& example, VarianceModel model, int divisions) {
  int m = example.techniqueCount();
  GridMinimum best{{}, std::numeric_limits<double>::infinity(), 0, 0, 0};
  std::vector<int> parts(m);
  std::function<void(int, int)> visit = [&](int k, int remaining) {
    if (k + 1 < m) {
      for (int n = 0; n <= remaining; ++n) {
        parts[k] = n;
        visit(k + 1, remaining - n);
      }
      return;
    }
    parts[k] = remaining;
    std::vector<double> alpha(m);
    for (int i = 0; i < m; ++i) alpha[i] = static_cast<double>(parts[i]) / divisions;
    ++best.points;
    VarianceStatus status = example.classify(alpha);
    if (status == VarianceStatus::SignedDensity || status == VarianceStatus::Undefined) {
      ++best.notADensity;
    } else if (status == VarianceStatus::Infinite) {
      ++best.infiniteVariance;
    } else if (double v = mixtureVariance(example, model, alpha).value; v < best.variance) {
      best.alpha = alpha;
      best.variance = v;
    }
  };
  visit(0, divisions);
  return best;
}

}  // namespace misalloc
