#include "scene/BrdfGrid.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "Error.h"
#include "NumberList.h"

namespace misalloc {
namespace {

const char* kForms = "seed000, general:RD0,RD1,N0,N1 or uniform:RD,RS,N";

std::vector<double> parseNumbers(const std::string& spec, const std::string& list, size_t expected) {
  return parseNumberList("--grid", spec, list, expected, std::string("forms: ") + kForms);
}

void checkParameters(const std::string& spec, double rhoD, double rhoS, double n) {
  if (rhoD < 0 || rhoS < 0 || rhoD + rhoS > 1 + 1e-6)
    throw InputError(fmt::format("--grid {}: albedos must satisfy ρd, ρs ≥ 0 and ρd + ρs ≤ 1", spec));
  if (n < 0 || n > 1e5) throw InputError(fmt::format("--grid {}: the Phong exponent must lie in [0, 1e5]", spec));
}

}  // namespace

float seed000Exponent(float x) { return float(-1.0 - 0.111211 / (0.1 * std::pow(double(x), 0.2) - 0.101101)); }

BrdfGrid makeBrdfGrid(const std::string& spec, int width, int height, const std::vector<SurfaceUv>& uv) {
  if (width <= 0 || height <= 0)
    throw InputError(fmt::format("--size {}x{}: both sides must be positive", width, height));
  if (uv.size() != size_t(width) * size_t(height))
    throw std::invalid_argument(fmt::format("{} surface points for a {}x{} grid", uv.size(), width, height));
  auto colon = spec.find(':');
  std::string kind = spec.substr(0, colon);
  std::string args = colon == std::string::npos ? "" : spec.substr(colon + 1);
  // The parameters at (u, v) ∈ (0,1)², u to the right, v down.
  std::function<PhongParameters(double, double)> at;
  if (kind == "seed000" && args.empty()) {
    at = [](double u, double v) {
      double rhoD = (1 - v) * (1 - v);  // [HS14] Sec. 5.2
      return PhongParameters{float(rhoD), float(1 - rhoD), seed000Exponent(float(u))};
    };
  } else if (kind == "general") {
    auto a = parseNumbers(spec, args, 4);
    if (a[2] <= 0 || a[3] <= 0) throw InputError(fmt::format("--grid {}: exponents must be positive", spec));
    checkParameters(spec, std::max(a[0], a[1]), 1 - std::max(a[0], a[1]), std::max(a[2], a[3]));
    checkParameters(spec, std::min(a[0], a[1]), 1 - std::min(a[0], a[1]), std::min(a[2], a[3]));
    at = [a](double u, double v) {
      double rhoD = a[0] + (a[1] - a[0]) * v;
      return PhongParameters{float(rhoD), float(1 - rhoD), float(a[2] * std::pow(a[3] / a[2], u))};
    };
  } else if (kind == "uniform") {
    auto a = parseNumbers(spec, args, 3);
    checkParameters(spec, a[0], a[1], a[2]);
    at = [a](double, double) { return PhongParameters{float(a[0]), float(a[1]), float(a[2])}; };
  } else {
    throw InputError(fmt::format("unknown --grid '{}' (expected {})", spec, kForms));
  }
  BrdfGrid grid{spec, width, height, {}};
  grid.pixels.reserve(uv.size());
  for (const SurfaceUv& p : uv) grid.pixels.push_back(at(p.u, p.v));
  return grid;
}

BrdfGrid makeBrdfGrid(const std::string& spec, int width, int height) {
  return makeBrdfGrid(spec, width, height, pixelCentres(width, height));
}

std::vector<SurfaceUv> pixelCentres(int width, int height) {
  std::vector<SurfaceUv> uv;
  if (width <= 0 || height <= 0) return uv;
  uv.reserve(size_t(width) * height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) uv.push_back({(x + 0.5) / width, (y + 0.5) / height});
  return uv;
}

}  // namespace misalloc
