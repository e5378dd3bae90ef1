#include "scene/Envmap.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <vector>

#include "Constants.h"
#include "Error.h"

namespace misalloc {
namespace {

constexpr int kMaxProceduralWidth = 16384;  // 16384 × 8192 texels: 1.5 GiB of RGB floats
// The brightest radiance rendered. A sample reaches about 3e6 times the radiance
// (Phong lobes up to n = 1e5, 4π sr, a blue texel whose luminance is 7 % of its
// value), so 1e30 keeps samples two orders below float's 3.4e38, where a brighter
// map would write Inf pixels; tests/test_stability.cpp renders 1e30 finite and unbiased.
constexpr double kMaxRadiance = 1e30;
constexpr char kAcceptedForms[] =
    "accepted forms: PATH (an OpenEXR file), constant, constant:R, cosk:K, sun, sun:THETA,PHI,RADIUS,RATIO";

InputError badSpec(const std::string& spec, const std::string& problem) {
  return InputError(fmt::format("--envmap {}: {}; {}", spec, problem, kAcceptedForms));
}

// Comma-separated finite numbers, exactly `count` of them.
std::vector<double> parseNumbers(const std::string& list, std::size_t count, const std::string& spec) {
  std::vector<double> numbers;
  for (std::size_t start = 0; start <= list.size();) {
    std::size_t end = std::min(list.find(',', start), list.size());
    const char* first = list.data() + start;
    const char* last = list.data() + end;
    double x = 0;
    auto [stop, error] = std::from_chars(first, last, x);
    if (error != std::errc() || stop != last || !std::isfinite(x))
      throw badSpec(spec, fmt::format("'{}' is not a finite number", std::string(first, last)));
    numbers.push_back(x);
    start = end + 1;
  }
  if (numbers.size() != count) throw badSpec(spec, fmt::format("expected {} number(s) after ':'", count));
  return numbers;
}

struct Rgb {
  double r, g, b;
};

double luminance(const Rgb& c) { return misalloc::luminance(c.r, c.g, c.b); }

// cos θ at the midpoint of sub-row s of n, in equal steps of cos θ: since dω = dφ
// d(cos θ), each sub-row covers the same solid angle, so a texel's solid-angle average
// is the plain mean over its sub-samples.
double cosThetaOfSubrow(int row, int s, int n, int height) {
  double top = std::cos(kPi * row / height), bottom = std::cos(kPi * (row + 1) / height);
  return top + (bottom - top) * (s + 0.5) / n;
}

// A radiance that depends on θ only (given as cos θ) is constant along each row, so a
// texel's average is the row's. Sixteen sub-rows keep a row that straddles the horizon
// at its covered fraction.
template <class RadianceOfCosTheta>
RgbImage rasteriseRows(int width, int height, RadianceOfCosTheta radiance) {
  constexpr int kSubrows = 16;
  RgbImage image{width, height, std::vector<float>(std::size_t(width) * std::size_t(height) * 3), {}};
  for (int row = 0; row < height; ++row) {
    Rgb sum{0, 0, 0};
    for (int s = 0; s < kSubrows; ++s) {
      Rgb value = radiance(cosThetaOfSubrow(row, s, kSubrows, height));
      sum = {sum.r + value.r, sum.g + value.g, sum.b + value.b};
    }
    float* out = image.rgb.data() + std::size_t(row) * std::size_t(width) * 3;
    for (int col = 0; col < width; ++col) {
      out[3 * col + 0] = float(sum.r / kSubrows);
      out[3 * col + 1] = float(sum.g / kSubrows);
      out[3 * col + 2] = float(sum.b / kSubrows);
    }
  }
  return image;
}

double texelSolidAngle(int row, int width, int height) {
  return 2 * kPi / width * (std::cos(kPi * row / height) - std::cos(kPi * (row + 1) / height));
}

// A disc of the sky: the directions within angular `radius` of (theta, phi).
struct Cap {
  double theta, phi, radius;

  double solidAngle() const { return 4 * kPi * std::sin(0.5 * radius) * std::sin(0.5 * radius); }  // 2π(1 − cos r)
};

// The fraction of texel (col, row)'s solid angle inside the cap, from n × n
// sub-samples of equal solid angle.
double capCoverage(const Cap& cap, int col, int row, int width, int height) {
  constexpr int n = 32;
  const double cosRadius = std::cos(cap.radius);
  double cosDeltaPhi[n];
  for (int a = 0; a < n; ++a) cosDeltaPhi[a] = std::cos(2 * kPi * (col + (a + 0.5) / n) / width - cap.phi);
  int inside = 0;
  for (int b = 0; b < n; ++b) {
    double cosTheta = cosThetaOfSubrow(row, b, n, height);
    double sinTheta = std::sqrt(std::max(0.0, 1 - cosTheta * cosTheta));
    for (int a = 0; a < n; ++a) {
      // The cosine of the angle to the cap's axis (spherical law of cosines).
      double cosAngle = sinTheta * std::sin(cap.theta) * cosDeltaPhi[a] + cosTheta * std::cos(cap.theta);
      inside += cosAngle >= cosRadius ? 1 : 0;
    }
  }
  return double(inside) / (n * n);
}

// Rows, and columns modulo W, that the cap can touch, with one texel of margin
// against rounding. A cap around a pole spans every column.
struct TexelRange {
  int rowLo, rowHi, colLo, colHi;
};

TexelRange candidateTexels(const Cap& cap, int width, int height) {
  TexelRange range;
  range.rowLo = std::max(0, int(std::floor((cap.theta - cap.radius) / kPi * height)) - 1);
  range.rowHi = std::min(height - 1, int(std::floor((cap.theta + cap.radius) / kPi * height)) + 1);
  if (cap.theta - cap.radius <= 0 || cap.theta + cap.radius >= kPi) {
    range.colLo = 0;
    range.colHi = width - 1;
    return range;
  }
  double halfWidth = std::asin(std::min(1.0, std::sin(cap.radius) / std::sin(cap.theta)));
  range.colLo = int(std::floor((cap.phi - halfWidth) / (2 * kPi) * width)) - 1;
  range.colHi = int(std::floor((cap.phi + halfWidth) / (2 * kPi) * width)) + 1;
  if (range.colHi - range.colLo + 1 >= width) {
    range.colLo = 0;
    range.colHi = width - 1;
  }
  return range;
}

// Adds `radiance` (white) over the cap, each texel weighted by its covered fraction.
// The sub-samples resolve the disc's outline to 1/32 of a texel; scaling the fractions
// to the cap's exact solid angle keeps the sun's power exact at any resolution, and
// a disc that falls between all sub-samples still lands in the texel of its centre.
void addDisc(RgbImage& image, const Cap& cap, double radiance) {
  const int width = image.width, height = image.height;
  std::vector<std::pair<std::size_t, double>> covered;  // texel, fraction of its solid angle
  double coveredSolidAngle = 0;
  TexelRange range = candidateTexels(cap, width, height);
  for (int row = range.rowLo; row <= range.rowHi; ++row) {
    for (int c = range.colLo; c <= range.colHi; ++c) {
      int col = ((c % width) + width) % width;
      double fraction = capCoverage(cap, col, row, width, height);
      if (fraction == 0) continue;
      covered.emplace_back(std::size_t(row) * std::size_t(width) + std::size_t(col), fraction);
      coveredSolidAngle += fraction * texelSolidAngle(row, width, height);
    }
  }
  if (covered.empty()) {
    int row = std::min(height - 1, int(cap.theta / kPi * height));
    int col = std::min(width - 1, int(cap.phi / (2 * kPi) * width));
    covered.emplace_back(std::size_t(row) * std::size_t(width) + std::size_t(col), 1.0);
    coveredSolidAngle = texelSolidAngle(row, width, height);
  }
  double scale = cap.solidAngle() / coveredSolidAngle;
  for (const auto& [texel, fraction] : covered)
    for (int c = 0; c < 3; ++c) image.rgb[3 * texel + c] += float(fraction * scale * radiance);
}

// A clear sky, bluish and brightest at the horizon, over a dim ground.
constexpr Rgb kSkyAtHorizon{0.55, 0.7, 1.0};
constexpr double kSkyZenithShare = 0.3;  // zenith radiance / horizon radiance
constexpr Rgb kGround{0.06, 0.05, 0.04};

Rgb skyRadiance(double cosTheta) {
  if (cosTheta <= 0) return kGround;
  double brightness = kSkyZenithShare + (1 - kSkyZenithShare) * (1 - cosTheta);
  return {brightness * kSkyAtHorizon.r, brightness * kSkyAtHorizon.g, brightness * kSkyAtHorizon.b};
}

Envmap constantMap(double radiance, int width) {
  Envmap map;
  map.image = rasteriseRows(width, width / 2, [&](double) { return Rgb{radiance, radiance, radiance}; });
  map.description = fmt::format("constant:{:g}", radiance);
  return map;
}

Envmap coskMap(double exponent, int width) {
  Envmap map;
  map.image = rasteriseRows(width, width / 2, [&](double cosTheta) {
    double value = cosTheta > 0 ? std::pow(cosTheta, exponent) : 0.0;
    return Rgb{value, value, value};
  });
  map.coskExponent = float(exponent);
  map.description = fmt::format("cosk:{:g}", exponent);
  return map;
}

// Angles in degrees, as in the spec.
Envmap sunMap(double theta, double phi, double radius, double ratio, int width) {
  Envmap map;
  map.image = rasteriseRows(width, width / 2, skyRadiance);
  double phiWrapped = phi - 360 * std::floor(phi / 360);
  addDisc(map.image, Cap{theta * kPi / 180, phiWrapped * kPi / 180, radius * kPi / 180},
          ratio * luminance(kSkyAtHorizon));
  map.description = fmt::format("sun:{:g},{:g},{:g},{:g}", theta, phi, radius, ratio);
  return map;
}

Envmap proceduralMap(const std::string& name, const std::string& arguments, bool hasArguments, const std::string& spec,
                     int width) {
  if (width < 2 || width > kMaxProceduralWidth)
    throw InputError(fmt::format("procedural envmap width {} is not in [2, {}]", width, kMaxProceduralWidth));
  if (name == "constant") {
    double radiance = hasArguments ? parseNumbers(arguments, 1, spec)[0] : 1.0;
    if (radiance < 0 || !std::isfinite(float(radiance)))
      throw badSpec(spec, "the radiance R must be ≥ 0 and finite as a float");
    return constantMap(radiance, width);
  }
  if (name == "cosk") {
    if (!hasArguments) throw badSpec(spec, "cosk needs its exponent, e.g. cosk:1");
    double exponent = parseNumbers(arguments, 1, spec)[0];
    if (exponent < 0 || !std::isfinite(float(exponent)))
      throw badSpec(spec, "the exponent K must be ≥ 0 and finite as a float");
    return coskMap(exponent, width);
  }
  std::vector<double> p = hasArguments ? parseNumbers(arguments, 4, spec) : std::vector<double>{40, 90, 0.5, 1e5};
  if (p[0] < 0 || p[0] > 180) throw badSpec(spec, "THETA must be in [0, 180] degrees");
  if (p[2] <= 0 || p[2] > 90) throw badSpec(spec, "RADIUS must be in (0, 90] degrees");
  if (p[3] <= 0 || !std::isfinite(float(p[3]))) throw badSpec(spec, "RATIO must be > 0 and finite as a float");
  return sunMap(p[0], p[1], p[2], p[3], width);
}

// Refuses a map brighter than kMaxRadiance, naming its first such value; a procedural
// map that overflowed float on rasterising is caught here too, as Inf.
void refuseOverflowingRadiance(const RgbImage& image, const std::string& spec) {
  for (std::size_t i = 0; i < image.rgb.size(); ++i) {
    if (image.rgb[i] <= float(kMaxRadiance)) continue;
    std::size_t pixel = i / 3;
    TexelLocation at{int(pixel % std::size_t(image.width)), int(pixel / std::size_t(image.width)), "RGB"[i % 3]};
    throw InputError(fmt::format(
        "--envmap {}: radiance {:g} at {} exceeds {:g}, the brightest that renders without overflowing float; "
        "scale the map down",
        spec, image.rgb[i], toString(at), kMaxRadiance));
  }
}

}  // namespace

Envmap makeEnvmap(const std::string& spec, int proceduralWidth, ReadWarnings* warnings) {
  std::size_t colon = spec.find(':');
  std::string name = spec.substr(0, colon);
  Envmap map;
  if (name == "constant" || name == "cosk" || name == "sun") {
    bool hasArguments = colon != std::string::npos;
    map = proceduralMap(name, hasArguments ? spec.substr(colon + 1) : "", hasArguments, spec, proceduralWidth);
  } else {
    std::error_code ignored;
    if (!std::filesystem::exists(spec, ignored)) throw badSpec(spec, "no such file");
    map.image = readExr(spec, warnings);
    map.image.alpha = {};  // a map is seen whole: its alpha is no coverage of ours
    map.description = spec;
  }
  refuseOverflowingRadiance(map.image, spec);
  map.description += fmt::format(" ({}×{})", map.image.width, map.image.height);
  return map;
}

Envmap envmapFromTexels(RgbImage texels, const std::string& name, ReadWarnings* warnings) {
  Envmap map;
  map.image = std::move(texels);
  map.image.alpha = {};
  checkImageValues(map.image, name, warnings);
  refuseOverflowingRadiance(map.image, name);
  map.description = fmt::format("{} ({}×{})", name, map.image.width, map.image.height);
  return map;
}

}  // namespace misalloc
