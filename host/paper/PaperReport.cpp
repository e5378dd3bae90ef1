#include "paper/PaperReport.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <stdexcept>

#include "alloc/HeuristicAllocation.h"
#include "alloc/SigmaAllocation.h"
#include "paper/Flatland.h"
#include "paper/MixtureOptimizer.h"
#include "paper/MixtureVariance.h"
#include "paper/MonteCarloStudy.h"
#include "paper/OptimalWeightsVariance.h"
#include "paper/PublishedValues.h"

namespace misalloc {

namespace {

using Values = std::map<std::string, std::string>;

// The Monte Carlo study matches verified_values.json's: 200 runs of 100 samples per technique.
constexpr StudyConfig kStudy{200, 100, 20240601};

std::string number(double v) {
  if (std::isnan(v)) return "undefined";
  if (std::isinf(v)) return v > 0 ? "infinite" : "-infinite";
  return fmt::format("{:.6g}", v);
}

std::string numbers(const std::vector<double>& v) {
  std::vector<std::string> parts;
  for (double x : v) parts.push_back(number(x));
  return fmt::format("({})", fmt::join(parts, ", "));
}

std::string variance(const VarianceValue& v) {
  switch (v.status) {
    case VarianceStatus::Finite:
      return number(v.value);
    case VarianceStatus::Infinite:
      return "infinite";
    case VarianceStatus::SignedDensity:
      return number(v.value) + " (formal: p < 0 where f = 0)";
    case VarianceStatus::Undefined:
      return "undefined (p < 0 where f != 0)";
  }
  return "";
}

std::vector<VarianceValue> techniqueVariances(const Example1D& example) {
  std::vector<VarianceValue> v;
  for (int k = 0; k < example.techniqueCount(); ++k) v.push_back(techniqueVariance(example, k));
  return v;
}

std::vector<double> valuesOf(const std::vector<VarianceValue>& variances) {
  std::vector<double> v;
  for (const VarianceValue& x : variances) v.push_back(x.value);
  return v;
}

std::string optimum(const OptimalMixture& best) {
  return fmt::format("{} at {}{}", number(best.variance), numbers(best.alpha),
                     best.converged ? "" : " (not converged)");
}

Values values000C() {
  Example1D printed = example000AppendixC(AppendixCNormalisation::AsPrinted);
  Example1D exact = example000AppendixC(AppendixCNormalisation::Exact);
  const std::vector<double>& costs = exact.costs();
  std::vector<double> unit(3, 1.0), equal(3, 1.0 / 3);
  Values v;
  v["I"] = number(printed.integral());
  v["s1 = int x"] = number(exact.pdf(0).normalisation());
  v["s2 = int (x^2 - x/pi)"] = number(exact.pdf(1).normalisation());
  v["s3 = int sin x"] = number(exact.pdf(2).normalisation());

  // First block: s2 = 8.764 as printed.
  std::vector<VarianceValue> techniques = techniqueVariances(printed);
  v["V1"] = variance(techniques[0]);
  v["V2 (s2 = 8.764)"] = variance(techniques[1]);
  v["V3"] = variance(techniques[2]);
  v["H(V1, V2, V3)"] = number(harmonicMean(valuesOf(techniques)));
  std::vector<double> alpha = heuristicWeights(valuesOf(techniques), unit).alpha;
  v["alpha, eq. 4.17"] = numbers(alpha);
  MixtureMoments atAlpha = mixtureMoments(printed, alpha), atEqual = mixtureMoments(printed, equal);
  VarianceValue vAlpha = oneSampleVariance(atAlpha, printed.integral());
  VarianceValue vEqual = oneSampleVariance(atEqual, printed.integral());
  v["V(alpha), eq. 4.5"] = variance(vAlpha);
  v["V(1/3, 1/3, 1/3)"] = variance(vEqual);
  v["gain equal -> heuristic (%)"] = number(100 * (vEqual.value / vAlpha.value - 1));
  v["lambda, eq. 4.11, at alpha"] = number(atAlpha.secondMoment);
  v["E_j, eq. 4.9, at alpha"] = numbers(atAlpha.techniqueSecondMoment);
  v["lambda at alpha = 1/3"] = number(atEqual.secondMoment);
  v["E_j at alpha = 1/3"] = numbers(atEqual.techniqueSecondMoment);
  GridMinimum grid = gridMinimum(printed, VarianceModel::OneSample, 100);
  std::vector<double> publishedArgmin = {0, 0.95, 0.05};  // verified_values.json "alpha_at_min"
  v["grid minimum of V (step 0.01)"] = fmt::format(
      "{} at {}; {} of {} grid mixtures are no density, e.g. V{} is {}", number(grid.variance), numbers(grid.alpha),
      grid.notADensity, grid.points, numbers(publishedArgmin), variance(oneSampleVariance(printed, publishedArgmin)));
  v["alpha in Fig. 4.1"] = numbers(alpha);
  v["minimum of V over valid mixtures"] = optimum(minimiseInefficiency(printed, VarianceModel::OneSample, unit));

  // Cost block: the exact s2.
  std::vector<double> exactVariances = valuesOf(techniqueVariances(exact));
  std::vector<double> alphaExact = heuristicWeights(exactVariances, unit).alpha;
  std::vector<double> alphaCost = heuristicWeights(exactVariances, costs).alpha;
  double vEqualExact = oneSampleVariance(exact, equal).value;
  double vAlphaExact = oneSampleVariance(exact, alphaExact).value;
  double vCost = oneSampleVariance(exact, alphaCost).value;
  v["alpha with costs, eq. 4.20 (exact s2)"] = numbers(alphaCost);
  v["V(alpha with costs)"] = number(vCost);
  double efficiency = inefficiency(unit, equal, vEqualExact) / inefficiency(unit, alphaExact, vAlphaExact);
  v["relative efficiency, equal cost"] = number(efficiency);
  v["relative efficiency, with costs"] =
      number(inefficiency(costs, equal, vEqualExact) / inefficiency(costs, alphaCost, vCost));
  v["Fig. 4.1 caption: efficiency gain (%)"] = number(100 * (efficiency - 1));
  v["Sec. 5.1: efficiency gain (%)"] = number(100 * (efficiency - 1));
  OptimalMixture best = minimiseInefficiency(exact, VarianceModel::OneSample, costs);
  v["cost-aware optimum (exact s2)"] =
      fmt::format("alpha = {}: cost x V = {}, {} x the efficiency of equal weights", numbers(best.alpha),
                  number(best.inefficiency), number(inefficiency(costs, equal, vEqualExact) / best.inefficiency));
  return v;
}

Values values002(int n) {
  Example1D example = example002(n);
  const std::vector<double>& costs = example.costs();
  double integral = example.integral();
  std::vector<double> unit(3, 1.0), equal(3, 1.0 / 3);
  std::vector<VarianceValue> techniques = techniqueVariances(example);
  std::vector<double> alpha = heuristicWeights(valuesOf(techniques), unit).alpha;
  std::vector<double> alphaCost = heuristicWeights(valuesOf(techniques), costs).alpha;
  MixtureMoments atEqual = mixtureMoments(example, equal), atAlpha = mixtureMoments(example, alpha);
  VarianceValue vEqual = oneSampleVariance(atEqual, integral), vAlpha = oneSampleVariance(atAlpha, integral);
  VarianceValue vCost = oneSampleVariance(example, alphaCost);
  double costEfficiency = inefficiency(costs, equal, vEqual.value) / inefficiency(costs, alphaCost, vCost.value);

  Values v;
  v["I"] = number(integral);
  v["V(alpha ~ 1/V[G])"] = variance(vAlpha);
  v["V(1/3, 1/3, 1/3)"] = variance(vEqual);
  if (n == 1) {
    v["int_a^pi x"] = number(example.pdf(0).normalisation());
    v["int_a^pi (x^2 - x/pi)"] = number(example.pdf(1).normalisation());
    v["int_a^pi sin x"] = number(example.pdf(2).normalisation());
    v["relative efficiency, equal cost"] = number(vEqual.value / vAlpha.value);
  }
  if (n <= 2) v["V[G1], V[G2], V[G3]"] = numbers(valuesOf(techniques));
  if (n == 3) v["V[G1], V[G2]"] = numbers({techniques[0].value, techniques[1].value});
  if (n >= 3) v["V[G3]"] = variance(techniques[2]);
  if (n <= 3) {
    v["alpha ~ 1/V[G]"] = numbers(alpha);
    v["gain (%)"] = number(100 * (vEqual.value / vAlpha.value - 1));
    v["relative efficiency, with costs"] = number(costEfficiency);
  }

  v["Table 3: V at alpha = 1/n"] = variance(vEqual);
  v["Table 3: V at alpha ~ 1/V[G]"] = variance(vAlpha);
  v["Table 3: eq. 44 at alpha = 1/n"] = number(oneSampleExcess(atEqual, equal, integral));
  v["Table 3: eq. 44 at alpha ~ 1/V[G]"] = number(oneSampleExcess(atAlpha, alpha, integral));
  v["Table 4: cost x V at alpha = 1/n"] = number(inefficiency(costs, equal, vEqual.value));
  v["Table 4: cost x V at alpha ~ 1/(cV)"] = number(inefficiency(costs, alphaCost, vCost.value));
  std::vector<double> sigmas = countIndependentSigmas(example);
  std::vector<double> alphaSigma = sigmaSqrtCWeights(sigmas, costs).alpha;
  v["Table 5: cost x V, n ~ sigma/sqrt(c)"] =
      number(inefficiency(costs, alphaSigma, countIndependentVariance(sigmas, alphaSigma)));
  v["Table 5: cost x V, equal count"] = number(inefficiency(costs, equal, countIndependentVariance(sigmas, equal)));
  return v;
}

Values values003(int n) {
  Example1D example = example003(n);
  int m = example.techniqueCount();
  OptimalMixture best = minimiseInefficiency(example, VarianceModel::MultiSample, example.costs());
  Values v;
  v["integral"] = number(example.integral());
  v["V, equal budget"] = variance(multiSampleVariance(example, std::vector<double>(m, 1.0 / m)));
  v["V minimum"] = number(best.variance) + (best.converged ? "" : " (not converged)");
  v["alpha at minimum"] = numbers(best.alpha);
  return v;
}

// [Kar19] Sec. 6.3, on map A (paper/Flatland.h).
constexpr const char* kFlatlandId = "001-6.3";
constexpr const char* kFlatlandTitle =
    "[Kar19] Sec. 6.3: flatland MIS compensation, HDR map x diffuse or sharp BRDF, c = 0.5 (map A of "
    "verified_values.json stands in for the paper's)";

Values values001Flatland() {
  FlatlandStudy diffuse(FlatlandBrdf::Diffuse), sharp(FlatlandBrdf::Sharp);
  auto gain = [](const FlatlandStudy& s, FlatlandPdf pdf) {
    return s.variance(FlatlandPdf::Original).oneSample / s.variance(pdf).oneSample;
  };
  auto withinBounds = [](const OptimalLambda& l) { return l.lower <= l.lambda && l.lambda <= l.upper; };
  Values v;
  v["diffuse, one-sample: NMSE(HDR only) / NMSE(MIS)"] =
      number(diffuse.hdrOnly() / diffuse.variance(FlatlandPdf::Original).oneSample);
  v["diffuse, one-sample gain over MIS: practical-ni"] = number(gain(diffuse, FlatlandPdf::PracticalNi));
  v["diffuse, one-sample gain over MIS: practical-nd"] = number(gain(diffuse, FlatlandPdf::PracticalNd));
  v["diffuse, one-sample gain over MIS: MIS-compensated"] = number(gain(diffuse, FlatlandPdf::Compensated));
  v["diffuse, one-sample gain over MIS: optimal"] = number(gain(diffuse, FlatlandPdf::Optimal));
  v["sharp, one-sample gain over MIS: practical-ni, practical-nd"] =
      numbers({gain(sharp, FlatlandPdf::PracticalNi), gain(sharp, FlatlandPdf::PracticalNd)});
  v["sharp, one-sample: MIS-compensated vs BRDF only"] =
      number(sharp.brdfOnly() / sharp.variance(FlatlandPdf::Compensated).oneSample);
  v["sharp, one-sample: MIS-compensated vs MIS"] = number(gain(sharp, FlatlandPdf::Compensated));
  v["int (p_comp - p_opt)^2 / int p_opt^2 (diffuse, sharp)"] =
      numbers({diffuse.compensatedVsOptimal(), sharp.compensatedVsOptimal()});
  v["lambda in [c F^2, F^2/c], eq. 10 (diffuse, sharp)"] =
      fmt::format("{} ({} in [{}, {}]), {} ({} in [{}, {}])", withinBounds(diffuse.lambda()) ? "holds" : "fails",
                  number(diffuse.lambda().lambda), number(diffuse.lambda().lower), number(diffuse.lambda().upper),
                  withinBounds(sharp.lambda()) ? "holds" : "fails", number(sharp.lambda().lambda),
                  number(sharp.lambda().lower), number(sharp.lambda().upper));
  return v;
}

// Every pdf's normalised variance (N = 1) for both BRDFs, one- and multi-sample.
void printFlatlandTable(std::ostream& out) {
  const std::pair<FlatlandPdf, const char*> pdfs[] = {{FlatlandPdf::Original, "HDR map (original)"},
                                                      {FlatlandPdf::PracticalNi, "practical-ni (eq. 14)"},
                                                      {FlatlandPdf::PracticalNd, "practical-nd (eq. 13)"},
                                                      {FlatlandPdf::Compensated, "MIS-compensated (eq. 6)"},
                                                      {FlatlandPdf::Optimal, "optimal (eq. 9)"}};
  out << fmt::format("\n  NMSE (N = 1) with the balance heuristic, c = 0.5:\n  {:<26} {:>14} {:>14} {:>14} {:>14}\n",
                     "HDR-map pdf", "diffuse, one", "diffuse, multi", "sharp, one", "sharp, multi");
  FlatlandStudy diffuse(FlatlandBrdf::Diffuse), sharp(FlatlandBrdf::Sharp);
  for (auto [pdf, name] : pdfs) {
    FlatlandVariance d = diffuse.variance(pdf), s = sharp.variance(pdf);
    out << fmt::format("  {:<26} {:>14} {:>14} {:>14} {:>14}\n", name, number(d.oneSample), number(d.multiSample),
                       number(s.oneSample), number(s.multiSample));
  }
  out << fmt::format("  {:<26} {:>14} {:>14} {:>14} {:>14}\n", "HDR map only", number(diffuse.hdrOnly()), "",
                     number(sharp.hdrOnly()), "");
  out << fmt::format("  {:<26} {:>14} {:>14} {:>14} {:>14}\n", "BRDF only", number(diffuse.brdfOnly()), "",
                     number(sharp.brdfOnly()), "");
}

void printComparison(const std::string& id, std::ostream& out) {
  Values ours = reproducedValues(id);
  out << fmt::format("  {:<40} {:<32} {:<32} {}\n", "quantity", "published", "ours", "verdict [source]");
  for (const PublishedValue& row : publishedValues(id)) {
    auto it = ours.find(row.quantity);
    if (it == ours.end()) throw std::logic_error(fmt::format("no value computed for '{}' of {}", row.quantity, id));
    out << fmt::format("  {:<40} {:<32} {:<32} {} [{}]\n", row.quantity, row.published ? row.published : "-",
                       it->second, row.verdict, row.source);
  }
}

// [Kon19]'s optimal weights against the balance heuristic at the same counts: equal ones
// and the balance heuristic's own best (unit costs), where every count is positive.
void printOptimalWeights(const Example1D& example, std::ostream& out) {
  const int m = example.techniqueCount();
  const std::vector<double> equal(m, 1.0 / m);
  const OptimalMixture best = minimiseInefficiency(example, VarianceModel::MultiSample, std::vector<double>(m, 1.0));
  out << fmt::format(
      "\n  Optimal MIS weights ([Kon19]): multi-sample variance (N = 1) at the same counts:\n"
      "  {:<36} {:>14} {:>14}   {}\n",
      "counts alpha", "balance", "optimal", "coefficients a = A^-1 b");
  for (const std::vector<double>& alpha : {equal, best.alpha}) {
    if (std::any_of(alpha.begin(), alpha.end(), [](double a) { return !(a > 0); })) {
      out << fmt::format("  {:<36} a technique without samples: no optimal weights\n", numbers(alpha));
      continue;
    }
    const OptimalWeightsSolution optimal = optimalWeightsVariance(example, alpha);
    out << fmt::format("  {:<36} {:>14} {:>14}   {}\n", numbers(alpha), variance(multiSampleVariance(example, alpha)),
                       variance(optimal.variance), optimal.a.empty() ? "-" : numbers(optimal.a));
  }
}

void printStudy(const Example1D& example, std::ostream& out) {
  out << fmt::format(
      "\n  Monte Carlo: {} runs of {} samples per technique (seed {}); every rule allocates from the same samples.\n"
      "  Cost x exact variance (N = 1) at the rule's alpha, for the balance heuristic with fixed counts\n"
      "  ([SHS16] eq. 21), or for sigma/sqrt(c) the count-independent estimator it allocates for ([SHS16] eq. 29):\n",
      kStudy.runs, kStudy.samplesPerTechnique, kStudy.seed);
  std::vector<RuleOutcome> outcomes;
  try {
    outcomes = runAllocationStudy(example, kStudy);
  } catch (const std::domain_error& e) {
    out << "  not run: " << e.what() << "\n";
    return;
  }
  out << fmt::format("  {:<36} {:<36} {:>12} {:>12} {:>12} {:>10} {:>10}\n", "rule", "mean alpha", "median", "p10",
                     "p90", "fallbacks", "Sec. 5.1");
  for (const RuleOutcome& r : outcomes)
    out << fmt::format("  {:<36} {:<36} {:>12} {:>12} {:>12} {:>10} {:>10}\n", allocationRuleName(r.rule),
                       numbers(r.meanAlpha), number(r.inefficiency.median), number(r.inefficiency.p10),
                       number(r.inefficiency.p90), r.fallbackRuns, r.boundaryRuns);
  if (std::optional<LinearHeuristicReference> ref = linearHeuristicReference(example.id())) {
    out << "  independent implementation (verified_values.json, not in the paper):\n";
    for (auto [name, q] : {std::pair{"linear, drop most negative", ref->dropMostNegative},
                           std::pair{"linear, min sample variance", ref->minSampleVariance}})
      out << fmt::format("  {:<36} {:<36} {:>12} {:>12} {:>12}\n", name, "", number(q.median), number(q.p10),
                         number(q.p90));
  }
}

}  // namespace

std::map<std::string, std::string> reproducedValues(const std::string& id) {
  if (id == kFlatlandId) return values001Flatland();
  Example1D example = paperExample(id);  // throws for an unknown id
  if (id == "000-C") return values000C();
  int n = id.back() - '0';
  return id.compare(0, 3, "002") == 0 ? values002(n) : values003(n);
}

std::vector<std::string> paperIds() {
  std::vector<std::string> ids = paperExampleIds();
  ids.push_back(kFlatlandId);
  return ids;
}

void listPaperExamples(std::ostream& out) {
  for (const std::string& id : paperIds())
    out << fmt::format("  {:<7} {}\n", id, id == kFlatlandId ? kFlatlandTitle : paperExample(id).title());
}

void printPaperExample(const std::string& id, std::ostream& out) {
  if (id == kFlatlandId) {
    out << kFlatlandTitle << "\n\n";
    printComparison(id, out);
    printFlatlandTable(out);
    return;
  }
  Example1D example = paperExample(id);
  out << example.title() << fmt::format("\n  costs {}\n\n", numbers(example.costs()));
  printComparison(id, out);
  printOptimalWeights(example, out);
  printStudy(example, out);
}

}  // namespace misalloc
