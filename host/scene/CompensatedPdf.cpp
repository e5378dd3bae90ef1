#include "scene/CompensatedPdf.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>

#include "Error.h"

namespace misalloc {

EnvmapPdf parseEnvmapPdf(const std::string& spec, const std::string& option) {
  const std::string compensated = "compensated";
  if (spec == "plain") return {};
  if (spec == compensated) return {EnvmapPdf::Kind::Compensated, 0.5};
  if (spec.rfind(compensated + ":", 0) == 0) {
    const char* first = spec.data() + compensated.size() + 1;
    const char* last = spec.data() + spec.size();
    double c = 0;
    auto [stop, error] = std::from_chars(first, last, c);
    if (error == std::errc() && stop == last && c > 0 && c <= 1) return {EnvmapPdf::Kind::Compensated, c};
    throw InputError(
        fmt::format("{} {}: C, the envmap technique's share of the samples, must lie in (0, 1]", option, spec));
  }
  throw InputError(fmt::format("{} '{}': expected plain, compensated or compensated:C", option, spec));
}

std::string envmapPdfName(const EnvmapPdf& pdf) {
  return pdf.compensated() ? fmt::format("compensated:{:g}", pdf.envmapFraction) : "plain";
}

double solidAngleMeanLuminance(const std::vector<double>& luminance, int width, int height) {
  constexpr double kPi = 3.14159265358979323846;
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

}  // namespace misalloc
