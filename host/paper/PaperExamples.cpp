#include "paper/PaperExamples.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <stdexcept>

#include "Constants.h"

namespace misalloc {

namespace {

const std::vector<double> kHavranSbertCosts = {1, 6.24, 3.28};  // [HS14] App. C, measured in C++

double parabola(double x) { return x * x - x / kPi; }  // h₂ = x² − x/π

std::vector<Density1D> productTechniques(double a, double b) {
  return {Density1D(
              "x", [](double x) { return x; }, a, b),
          Density1D("x^2-x/pi", parabola, a, b),
          Density1D(
              "sin x", [](double x) { return std::sin(x); }, a, b)};
}

double productIntegrand(double x) { return x * parabola(x) * std::sin(x); }

std::invalid_argument unknownExample(const std::string& what) {
  return std::invalid_argument(
      fmt::format("unknown paper example '{}'; valid ids: {}", what, fmt::join(paperExampleIds(), ", ")));
}

}  // namespace

Example1D example000AppendixC(AppendixCNormalisation normalisation) {
  double a = 0, b = kPi;
  std::vector<Density1D> pdfs = productTechniques(a, b);
  if (normalisation == AppendixCNormalisation::AsPrinted)
    pdfs[1] = Density1D("(x^2-x/pi)/8.764", parabola, a, b, 8.764);
  return Example1D("000-C", "[HS14] App. C: f = x (x^2 - x/pi) sin x on [0, pi]; techniques x, x^2 - x/pi, sin x", a, b,
                   productIntegrand, pdfs, kHavranSbertCosts);
}

Example1D example002(int number) {
  double a = 3 / (2 * kPi), b = kPi;
  Function1D f;
  std::string integrand;
  switch (number) {
    case 1:
      f = productIntegrand;
      integrand = "x (x^2 - x/pi) sin x";
      break;
    case 2:
      f = [](double x) { return parabola(x) * std::sin(x) * std::sin(x); };
      integrand = "(x^2 - x/pi) sin^2 x";
      break;
    case 3:
      f = [](double x) { return x + parabola(x) + std::sin(x); };
      integrand = "x + (x^2 - x/pi) + sin x";
      break;
    case 4:
      // [SHS16] eq. 55 divides by the printed constants, 8.764 included.
      f = [](double x) { return x / 4.82082 + parabola(x) / 8.764 + std::sin(x) / 1.88816; };
      integrand = "x/4.82082 + (x^2 - x/pi)/8.764 + sin x/1.88816";
      break;
    default:
      throw unknownExample(fmt::format("002-{}", number));
  }
  return Example1D(fmt::format("002-{}", number),
                   fmt::format("[SHS16] App. A, Example {}: f = {} on [3/(2pi), pi]; techniques x, x^2 - x/pi, sin x",
                               number, integrand),
                   a, b, f, productTechniques(a, b), kHavranSbertCosts);
}

Example1D example003(int number) {
  auto gaussians = [](std::vector<std::pair<double, double>> params, double a, double b) {
    std::vector<Density1D> pdfs;
    for (auto [mean, sigma] : params) pdfs.push_back(truncatedGaussian(mean, sigma, a, b));
    return pdfs;
  };
  auto rootPlusSine = [](double x) { return std::sqrt(x) + std::sin(x); };
  auto phi = normalPdf;
  double a, b;
  Function1D f;
  std::string integrand;
  std::vector<Density1D> pdfs;
  switch (number) {
    case 1:
      a = 0.01, b = 3.5 * kPi;
      f = rootPlusSine, integrand = "sqrt x + sin x on [0.01, 3.5 pi]";
      pdfs = gaussians({{2, 1}, {8, 2}}, a, b);
      break;
    case 2:
      a = -4, b = 4;
      f = [phi](double x) { return phi(x, -1.5, 1) + 2 * phi(x, 1.5, 0.75); };
      integrand = "phi(-1.5,1) + 2 phi(1.5,0.75) on [-4, 4]";
      pdfs = gaussians({{-1.5, 1}, {1.5, 0.75}}, a, b);
      break;
    case 3:
      a = 0.01, b = kPi / 2;
      f = rootPlusSine, integrand = "sqrt x + sin x on [0.01, pi/2]";
      pdfs = {Density1D(
                  "2-x", [](double x) { return 2 - x; }, a, b),
              Density1D(
                  "sin^2 x", [](double x) { return std::sin(x) * std::sin(x); }, a, b)};
      break;
    case 4:
      a = -3, b = 3;
      f = [phi](double x) { return phi(x, -1.8, 1) + 2 * phi(x, 1.5, 0.75) + 3 * phi(x, -0.5, 0.5); };
      integrand = "phi(-1.8,1) + 2 phi(1.5,0.75) + 3 phi(-0.5,0.5) on [-3, 3]";
      pdfs = gaussians({{-1.5, 1}, {1.5, 0.75}, {-0.5, 1}}, a, b);
      break;
    case 5:
      a = -3, b = 3;
      f = [phi](double x) {
        return phi(x, -1.8, 1) + 6 * phi(x, 1.5, 0.75) + 3 * phi(x, -0.5, 0.5) + 3 * phi(x, 0.5, 0.5);
      };
      integrand = "phi(-1.8,1) + 6 phi(1.5,0.75) + 3 phi(-0.5,0.5) + 3 phi(0.5,0.5) on [-3, 3]";
      pdfs = gaussians({{-1.5, 1}, {1.5, 0.75}, {-0.5, 1}, {0.5, 1}}, a, b);
      break;
    case 6:
      a = 3 / (2 * kPi), b = kPi;
      f = [](double x) { return parabola(x) * std::sin(x) * std::sin(x); };
      integrand = "(x^2 - x/pi) sin^2 x on [3/(2pi), pi]";
      pdfs = productTechniques(a, b);
      break;
    default:
      throw unknownExample(fmt::format("003-{}", number));
  }
  std::vector<std::string> names;
  for (const Density1D& p : pdfs) names.push_back(p.name());
  return Example1D(fmt::format("003-{}", number),
                   fmt::format("[SS23] Sec. 6.1, Example {}: f = {}; pdfs {}", number, integrand, fmt::join(names, ", ")),
                   a, b, f, pdfs, std::vector<double>(pdfs.size(), 1.0));
}

std::vector<std::string> paperExampleIds() {
  return {"000-C", "002-1", "002-2", "002-3", "002-4", "003-1", "003-2", "003-3", "003-4", "003-5", "003-6"};
}

Example1D paperExample(const std::string& id) {
  if (id == "000-C") return example000AppendixC(AppendixCNormalisation::Exact);
  for (int n = 1; n <= 4; ++n)
    if (id == fmt::format("002-{}", n)) return example002(n);
  for (int n = 1; n <= 6; ++n)
    if (id == fmt::format("003-{}", n)) return example003(n);
  throw unknownExample(id);
}

}  // namespace misalloc
