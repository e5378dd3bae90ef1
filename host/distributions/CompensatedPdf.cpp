#include "distributions/CompensatedPdf.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <string_view>

#include "Constants.h"
#include "Error.h"

namespace misalloc {

namespace {

// The number that is the whole of text; nullopt if there is none or more follows it.
template <typename T>
std::optional<T> wholeNumber(std::string_view text) {
  T value{};
  auto [stop, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error == std::errc() && stop == text.data() + text.size()) return value;
  return std::nullopt;
}

// The number after "name:" in spec, whole.
template <typename T>
std::optional<T> parameterOf(std::string_view spec, const std::string& name) {
  return wholeNumber<T>(spec.substr(name.size() + 1));
}

bool hasParameter(const std::string& spec, const std::string& name) { return spec.rfind(name + ":", 0) == 0; }

bool cellsAcrossAllowed(int n, int most) { return n >= kMinPixelCellsAcross && n <= most && (n & (n - 1)) == 0; }

}  // namespace

EnvmapPdf parseEnvmapPdf(const std::string& spec, const std::string& option) {
  const std::string compensated = "compensated", pixelOptimal = "optimal-pixel";
  if (spec == "plain") return {};
  if (spec == "optimal") return {EnvmapPdf::Kind::Optimal, 0.5};
  if (spec == pixelOptimal) return {EnvmapPdf::Kind::PixelOptimal, 0.5};
  if (spec == compensated) return {EnvmapPdf::Kind::Compensated, 0.5};
  if (hasParameter(spec, compensated)) {
    const std::optional<double> c = parameterOf<double>(spec, compensated);
    if (c && *c > 0 && *c <= 1) return {EnvmapPdf::Kind::Compensated, *c};
    throw InputError(
        fmt::format("{} {}: C, the envmap technique's share of the samples, must lie in (0, 1]", option, spec));
  }
  if (hasParameter(spec, pixelOptimal)) {
    const std::size_t slash = spec.find('/');
    const std::string cells = spec.substr(0, slash);
    const std::optional<int> n = parameterOf<int>(cells, pixelOptimal);
    if (!n || !cellsAcrossAllowed(*n, kMaxPixelCellsAcross))
      throw InputError(fmt::format("{} {}: N, the cells across the map, must be a power of two from {} to {}", option,
                                   spec, kMinPixelCellsAcross, kMaxPixelCellsAcross));
    EnvmapPdf pdf{EnvmapPdf::Kind::PixelOptimal, 0.5, *n, std::min(*n, kDefaultPilotCellsAcross)};
    if (slash == std::string::npos) return pdf;
    const std::optional<int> pilot = wholeNumber<int>(std::string_view(spec).substr(slash + 1));
    if (!pilot || !cellsAcrossAllowed(*pilot, *n))
      throw InputError(fmt::format("{} {}: P, the pilot's cells across the map, must be a power of two from {} to N",
                                   option, spec, kMinPixelCellsAcross));
    pdf.pilotCellsAcross = *pilot;
    return pdf;
  }
  throw InputError(
      fmt::format("{} '{}': expected plain, compensated, compensated:C, optimal, optimal-pixel, optimal-pixel:N or "
                  "optimal-pixel:N/P",
                  option, spec));
}

std::string envmapPdfName(const EnvmapPdf& pdf) {
  switch (pdf.kind) {
    case EnvmapPdf::Kind::Compensated:
      return fmt::format("compensated:{:g}", pdf.envmapFraction);
    case EnvmapPdf::Kind::Optimal:
      return "optimal";
    case EnvmapPdf::Kind::PixelOptimal: {
      const bool defaultPilot = pdf.pilotCellsAcross == std::min(pdf.cellsAcross, kDefaultPilotCellsAcross);
      if (!defaultPilot) return fmt::format("optimal-pixel:{}/{}", pdf.cellsAcross, pdf.pilotCellsAcross);
      return pdf.cellsAcross == kDefaultPixelCellsAcross ? "optimal-pixel"
                                                         : fmt::format("optimal-pixel:{}", pdf.cellsAcross);
    }
    case EnvmapPdf::Kind::Plain:
      break;
  }
  return "plain";
}

double solidAngleMeanLuminance(const std::vector<double>& luminance, int width, int height) {
  double integral = 0;  // ∫ L dω / (2π/W)
  for (int row = 0; row < height; ++row) {
    double rowSum = 0;
    for (int col = 0; col < width; ++col) rowSum += luminance[std::size_t(row) * width + col];
    integral += rowSum * (std::cos(kPi * row / height) - std::cos(kPi * (row + 1) / height));
  }
  return integral * (2 * kPi / width) / (4 * kPi);
}

double compensatedLuminance(double luminance, double meanLuminance, double envmapFraction) {
  const double threshold = 2 * (1 - envmapFraction) * meanLuminance;  // [Kar19] eq. 14
  const double excess = luminance - threshold;
  return excess > 1e-6 * threshold ? excess : 0.0;
}

double misCompensated(double f, double q, double F, double c) { return std::max(0.0, f / (c * F) - q / c); }

namespace {

// [Kar19] eq. 9 with 1/√(cλ) and q/c given, so that λ's bisection computes them once.
double optimalFreeScaled(double f, double qOverC, double inverseRoot) {
  return std::max(0.0, f * inverseRoot - qOverC);
}

}  // namespace

double optimalFree(double f, double q, double lambda, double c) {
  return optimalFreeScaled(f, q / c, 1 / std::sqrt(c * lambda));
}

OptimalLambda solveOptimalLambda(const double* f, const double* q, const double* w, std::size_t n, double F, double c) {
  OptimalLambda bracket{0, c * F * F, F * F / c};
  std::vector<double> qOverC(q, q + n);
  for (double& v : qOverC) v /= c;
  double lo = bracket.lower, hi = bracket.upper;
  // λ to 12 digits: far below what a tabulated pdf resolves.
  while (hi - lo > 1e-12 * hi) {
    const double mid = 0.5 * (lo + hi), inverseRoot = 1 / std::sqrt(c * mid);
    double mass = 0;
    for (std::size_t i = 0; i < n; ++i) mass += w[i] * optimalFreeScaled(f[i], qOverC[i], inverseRoot);
    (mass > 1 ? lo : hi) = mid;
  }
  bracket.lambda = 0.5 * (lo + hi);
  return bracket;
}

}  // namespace misalloc
