#include "paper/MixtureOptimizer.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <numeric>
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

double halfSpaceMargin(const std::vector<double>& a) { return 1e-12 * std::sqrt(dot(a, a)); }

// Projection onto the valid mixtures {α in the simplex : p_α ≥ 0 at every probe}, a
// convex polytope: Dykstra's alternating projections onto the simplex and the probe
// half-spaces found violated so far, adding the most violated probe until none is.
// The half-spaces keep a relative margin of 1e-12 so the result is strictly valid.
class ValidMixtureProjection {
  public:
    explicit ValidMixtureProjection(const Example1D& example) : example_(example) {}

    std::vector<double> operator()(const std::vector<double>& v) {
        constexpr int kMaxCuts = 32;
        for (;;) {
            std::vector<double> x = dykstra(v);
            std::optional<std::vector<double>> cut = example_.mostViolatedProbe(x);
            if (!cut || cuts_.size() == kMaxCuts) return x;
            cuts_.push_back(*cut);
        }
    }

  private:
    std::vector<double> dykstra(const std::vector<double>& v) const {
        if (cuts_.empty()) return projectToSimplex(v);
        constexpr int kMaxSweeps = 100000;
        std::size_t m = v.size();
        std::vector<std::vector<double>> increment(cuts_.size() + 1, std::vector<double>(m, 0.0));
        std::vector<double> x = v, y(m);
        for (int sweep = 0; sweep < kMaxSweeps; ++sweep) {
            double change = 0;
            for (std::size_t s = 0; s <= cuts_.size(); ++s) {
                for (std::size_t k = 0; k < m; ++k) y[k] = x[k] + increment[s][k];
                std::vector<double> z = s == 0 ? projectToSimplex(y) : projectToHalfSpace(y, cuts_[s - 1]);
                for (std::size_t k = 0; k < m; ++k) {
                    increment[s][k] = y[k] - z[k];
                    change = std::max(change, std::abs(z[k] - x[k]));
                }
                x = z;
            }
            if (change < 1e-16) break;
        }
        return x;
    }

    // Onto {α : a·α ≥ margin}.
    static std::vector<double> projectToHalfSpace(std::vector<double> y, const std::vector<double>& a) {
        double shortfall = halfSpaceMargin(a) - dot(a, y);
        if (shortfall > 0)
            for (std::size_t k = 0; k < y.size(); ++k) y[k] += shortfall / dot(a, a) * a[k];
        return y;
    }

    const Example1D& example_;
    std::vector<std::vector<double>> cuts_;
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
    Evaluation e{true, v, cost * v, std::vector<double>(m)};
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
    constexpr double kArmijo = 1e-4, kStationarity = 1e-11, kMinStep = 1e-30;

    std::vector<double> x(m, 1.0 / m);
    Evaluation e = evaluate(example, model, costs, x);
    if (!e.valid)
        throw std::domain_error("minimiseInefficiency: equal weights are not a valid mixture for example " +
                                example.id());
    std::deque<double> history{e.inefficiency};
    ValidMixtureProjection project(example);
    double spectralStep = 1;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
        std::vector<double> trial(m), d(m);
        for (int k = 0; k < m; ++k) trial[k] = x[k] - e.gradient[k];
        std::vector<double> unitStep = project(trial);
        double stationarity = 0;
        for (int k = 0; k < m; ++k) stationarity = std::max(stationarity, std::abs(unitStep[k] - x[k]));
        if (stationarity <= kStationarity * (1 + std::abs(e.inefficiency))) return {x, e.variance, e.inefficiency, true};

        for (int k = 0; k < m; ++k) trial[k] = x[k] - spectralStep * e.gradient[k];
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
