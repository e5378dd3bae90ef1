#include "paper/Quadrature.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace misalloc {

namespace {

// QUADPACK's qk15 abscissae (x ≥ 0) and weights; the 7-point Gauss rule uses the
// odd-indexed abscissae.
constexpr double kKronrodNodes[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                                     0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                                     0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                                     0.207784955007898467600689403773245, 0.0};
constexpr double kKronrodWeights[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                                       0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                                       0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                                       0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kGaussWeights[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                                     0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Panel {
  double a, b;
  std::vector<double> value, error, absValue;
  double priority = 0;
};

Panel evaluatePanel(const VectorIntegrand& f, int components, double a, double b) {
  Panel panel{a, b, std::vector<double>(components), std::vector<double>(components), std::vector<double>(components)};
  std::vector<double> gauss(components, 0.0), values(components);
  double center = 0.5 * (a + b), halfWidth = 0.5 * (b - a);
  auto accumulate = [&](double x, double kronrodWeight, double gaussWeight) {
    f(x, values.data());
    for (int c = 0; c < components; ++c) {
      panel.value[c] += kronrodWeight * values[c];
      panel.absValue[c] += kronrodWeight * std::abs(values[c]);
      gauss[c] += gaussWeight * values[c];
    }
  };
  for (int i = 0; i < 7; ++i) {
    double gaussWeight = i % 2 == 1 ? kGaussWeights[i / 2] : 0.0;
    accumulate(center - halfWidth * kKronrodNodes[i], kKronrodWeights[i], gaussWeight);
    accumulate(center + halfWidth * kKronrodNodes[i], kKronrodWeights[i], gaussWeight);
  }
  accumulate(center, kKronrodWeights[7], kGaussWeights[3]);
  for (int c = 0; c < components; ++c) {
    panel.value[c] *= halfWidth;
    panel.absValue[c] *= halfWidth;
    panel.error[c] = std::abs(panel.value[c] - gauss[c] * halfWidth);
  }
  return panel;
}

}  // namespace

QuadratureResult integrateAdaptive(const VectorIntegrand& f, int components, double a, double b, double relTol,
                                   int maxPanels) {
  constexpr int kInitialPanels = 16;
  std::vector<Panel> panels;
  for (int i = 0; i < kInitialPanels; ++i)
    panels.push_back(evaluatePanel(f, components, a + (b - a) * i / kInitialPanels,
                                   i + 1 == kInitialPanels ? b : a + (b - a) * (i + 1) / kInitialPanels));

  // Running totals, updated as panels are split.
  std::vector<double> total(components, 0.0), error(components, 0.0), absTotal(components, 0.0);
  auto add = [&](const Panel& p, double sign) {
    for (int c = 0; c < components; ++c) {
      total[c] += sign * p.value[c];
      error[c] += sign * p.error[c];
      absTotal[c] += sign * p.absValue[c];
    }
  };
  for (const Panel& p : panels) add(p, 1);
  // Errors are compared across components relative to each one's ∫|f_c| as first
  // estimated; a component that is identically 0 gets weight 1.
  std::vector<double> scale = absTotal;
  auto prioritise = [&](Panel& p) {
    p.priority = 0;
    for (int c = 0; c < components; ++c) p.priority += p.error[c] / (scale[c] > 0 ? scale[c] : 1.0);
    return std::isfinite(p.priority);
  };
  for (Panel& p : panels)
    if (!prioritise(p)) return {total, false};
  auto lower = [](const Panel& x, const Panel& y) { return x.priority < y.priority; };
  std::make_heap(panels.begin(), panels.end(), lower);

  auto finished = [&]() {
    for (int c = 0; c < components; ++c)
      if (!(error[c] <= relTol * absTotal[c])) return false;
    return true;
  };
  while (!finished()) {
    std::pop_heap(panels.begin(), panels.end(), lower);
    Panel worst = std::move(panels.back());
    panels.pop_back();
    double mid = 0.5 * (worst.a + worst.b);
    if (static_cast<int>(panels.size()) + 2 > maxPanels || !(worst.a < mid && mid < worst.b)) return {total, false};
    add(worst, -1);
    for (Panel half : {evaluatePanel(f, components, worst.a, mid), evaluatePanel(f, components, mid, worst.b)}) {
      if (!prioritise(half)) return {total, false};
      add(half, 1);
      panels.push_back(std::move(half));
      std::push_heap(panels.begin(), panels.end(), lower);
    }
  }
  // Re-add from scratch: the running sums carry the round-off of every split.
  std::fill(total.begin(), total.end(), 0.0);
  for (const Panel& p : panels)
    for (int c = 0; c < components; ++c) total[c] += p.value[c];
  return {total, true};
}

double integrate(const std::function<double(double)>& f, double a, double b) {
  QuadratureResult r = integrateAdaptive([&](double x, double* v) { v[0] = f(x); }, 1, a, b);
  if (!r.converged) throw std::runtime_error("integrate: adaptive quadrature did not converge");
  return r.value[0];
}

}  // namespace misalloc
