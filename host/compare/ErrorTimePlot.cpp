#include "compare/ErrorTimePlot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace misalloc {
namespace {

constexpr double kWidth = 800, kHeight = 480;
constexpr double kLeft = 70, kRight = 250, kTop = 40, kBottom = 55;  // margins; the legend sits right

// A colour per method that stays the same across plots.
const char* methodColour(Method m) {
  switch (m) {
    case Method::Envmap:
      return "#1f77b4";
    case Method::Brdf:
      return "#d62728";
    case Method::Equal:
      return "#000000";
    case Method::Heuristic:
      return "#2ca02c";
    case Method::SigmaSqrtC:
      return "#9467bd";
    case Method::Linear:
      return "#8c564b";
    case Method::Exact:
      return "#ff7f0e";
    case Method::Oracle:
      return "#7f7f7f";
    case Method::Ris:
      return "#17becf";
  }
  return "#000000";
}

// A logarithmic axis over whole decades around [lo, hi].
struct LogAxis {
  double lo, hi;    // decades' exponents
  double from, to;  // pixels

  LogAxis(double minValue, double maxValue, double from, double to)
      : lo(std::floor(std::log10(minValue))), hi(std::ceil(std::log10(maxValue))), from(from), to(to) {
    if (hi <= lo) hi = lo + 1;
  }
  double operator()(double v) const { return from + (std::log10(v) - lo) / (hi - lo) * (to - from); }
  // 1, 2 and 5 times each power of ten on the axis.
  std::vector<double> ticks() const {
    std::vector<double> values;
    for (double e = lo; e <= hi; ++e)
      for (int m : {1, 2, 5})
        if (std::log10(m) + e <= hi + 1e-9) values.push_back(m * std::pow(10.0, e));
    return values;
  }
};

// A dash pattern per pdf, in the order the scene ran them: solid for the first.
const char* pdfDash(size_t index) {
  static const char* const dashes[] = {"", "7,4", "2,3", "9,3,2,3"};
  return dashes[index % (sizeof(dashes) / sizeof(dashes[0]))];
}

std::string tickLabel(double value) { return fmt::format("{:g}", value); }

std::string axes(const LogAxis& x, const LogAxis& y) {
  std::string svg;
  for (double v : x.ticks()) {
    svg += fmt::format(R"(<line x1="{0:.1f}" y1="{1}" x2="{0:.1f}" y2="{2}" stroke="#ddd"/>)", x(v), kTop,
                       kHeight - kBottom);
    svg += fmt::format(R"(<text x="{:.1f}" y="{}" text-anchor="middle" font-size="11">{}</text>)", x(v),
                       kHeight - kBottom + 16, tickLabel(v));
  }
  for (double v : y.ticks()) {
    svg += fmt::format(R"(<line x1="{0}" y1="{1:.1f}" x2="{2}" y2="{1:.1f}" stroke="#ddd"/>)", kLeft, y(v),
                       kWidth - kRight);
    svg += fmt::format(R"(<text x="{}" y="{:.1f}" text-anchor="end" font-size="11">{}</text>)", kLeft - 6, y(v) + 4,
                       tickLabel(v));
  }
  svg += fmt::format(R"(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#000"/>)", kLeft, kTop,
                     kWidth - kLeft - kRight, kHeight - kTop - kBottom);
  svg += fmt::format(R"(<text x="{}" y="{}" text-anchor="middle" font-size="13">wall time per render (s)</text>)",
                     (kLeft + kWidth - kRight) / 2, kHeight - 12);
  svg += fmt::format(
      R"svg(<text x="16" y="{0}" text-anchor="middle" font-size="13" transform="rotate(-90 16 {0})">RMSE×1000 (reference-corrected)</text>)svg",
      (kTop + kHeight - kBottom) / 2);
  return svg;
}

// One method's line through its budgets, its error bars and its legend entry in `row`.
std::string methodLine(const MethodSummary& m, const std::string& name, const char* colour, const char* dash,
                       const LogAxis& x, const LogAxis& y, double legendY) {
  std::string svg, points;
  for (const BudgetStats& b : m.budgets) {
    double px = x(b.wallSeconds), py = y(b.rmseX1000);
    points += fmt::format("{:.1f},{:.1f} ", px, py);
    double lo = std::max(b.rmseX1000 - b.rmseSpreadX1000, 0.5 * b.rmseX1000);
    svg += fmt::format(R"(<line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="{3}"/>)", px, y(lo),
                       y(b.rmseX1000 + b.rmseSpreadX1000), colour);
    svg += fmt::format(
        R"(<circle cx="{:.1f}" cy="{:.1f}" r="3" fill="{}"><title>{} {} spp: {:.2f} at {:.3g} s</title></circle>)", px,
        py, colour, name, b.budget, b.rmseX1000, b.wallSeconds);
  }
  svg += fmt::format(R"(<polyline points="{}" fill="none" stroke="{}" stroke-width="1.5" stroke-dasharray="{}"/>)",
                     points, colour, dash) +
         "\n";
  const double ly = legendY;
  svg += fmt::format(R"(<line x1="{0}" y1="{1}" x2="{2}" y2="{1}" stroke="{3}" stroke-width="2" stroke-dasharray="{4}"/>)",
                     kWidth - kRight + 12, ly, kWidth - kRight + 36, colour, dash);
  svg += fmt::format(R"(<text x="{}" y="{}" font-size="12">{}</text>)", kWidth - kRight + 42, ly + 4, name) + "\n";
  return svg;
}

}  // namespace

std::string errorTimePlotSvg(const SceneGroup& scene) {
  double tMin = std::numeric_limits<double>::infinity(), tMax = 0, eMin = tMin, eMax = 0;
  for (const CaseSummary* c : scene.cases)
    for (const MethodSummary& m : c->methods)
      for (const BudgetStats& b : m.budgets) {
        if (!(b.wallSeconds > 0 && b.rmseX1000 > 0)) continue;
        tMin = std::min(tMin, b.wallSeconds), tMax = std::max(tMax, b.wallSeconds);
        eMin = std::min(eMin, std::max(b.rmseX1000 - b.rmseSpreadX1000, 0.5 * b.rmseX1000));
        eMax = std::max(eMax, b.rmseX1000 + b.rmseSpreadX1000);
      }
  std::string svg = fmt::format(
      R"(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{1}" viewBox="0 0 {0} {1}" font-family="sans-serif">)"
      "\n<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n",
      kWidth, kHeight);
  svg += fmt::format(R"(<text x="{}" y="24" text-anchor="middle" font-size="15">{}: error against time</text>)",
                     (kLeft + kWidth - kRight) / 2, scene.label) +
         "\n";
  if (tMax == 0) return svg + "<text x=\"100\" y=\"100\">no finished runs</text>\n</svg>\n";
  LogAxis x(tMin, tMax, kLeft, kWidth - kRight), y(eMin, eMax, kHeight - kBottom, kTop);
  svg += axes(x, y) + "\n";
  int lines = 0, row = 0;
  for (const CaseSummary* c : scene.cases)
    for (const MethodSummary& m : c->methods) lines += m.budgets.empty() ? 0 : 1;
  // Legend rows 20 px apart, closer where many lines share the plot's height.
  const double spacing = std::min(20.0, (kHeight - kTop - kBottom - 10) / std::max(1, lines));
  for (size_t pdf = 0; pdf < scene.cases.size(); ++pdf)
    for (const MethodSummary& m : scene.cases[pdf]->methods) {
      if (m.budgets.empty()) continue;
      const std::string name = scene.cases.size() > 1
                                   ? methodName(m.method) + " / " + caseVariant(scene.cases[pdf]->info)
                                   : methodName(m.method);
      svg += methodLine(m, name, methodColour(m.method), pdfDash(pdf), x, y, kTop + 10 + spacing * row++);
    }
  return svg + "</svg>\n";
}

}  // namespace misalloc
