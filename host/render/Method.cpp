#include "render/Method.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>

#include "Error.h"
#include "KernelCode.h"

namespace misalloc {
namespace {

constexpr Estimator kBalance = Estimator::MultiSample;

// One row per method, in the enum's order, which is the order of the tables.
constexpr MethodTraits kMethods[] = {
    // method, name, split, searches weights, estimator, statistics, stores samples, envmap only
    {Method::Envmap, "envmap", Split::Fixed, false, kBalance, 0, false, true},
    {Method::Brdf, "brdf", Split::Fixed, false, kBalance, 0, false, false},
    {Method::Equal, "equal", Split::Fixed, false, kBalance, 0, false, false},
    // [HS14] eq. 4.20 from V_k, eq. 4.18
    {Method::Heuristic, "heuristic", Split::Staged, false, kBalance, MA_STATS_TECHNIQUE, false, false},
    // [SHS16] eq. 31 from σ_k, eq. 28
    {Method::SigmaSqrtC, "sigma-sqrt-c", Split::Staged, false, Estimator::CountIndependent, MA_STATS_BALANCE, false,
     false},
    // [SS23] eq. 14; its negative weights by eq. 19 need the samples
    {Method::Linear, "linear", Split::Staged, false, kBalance, MA_STATS_LINEAR, true, false},
    // The grid search reads each stage's samples into sums of its own, per combination.
    {Method::Exact, "exact", Split::Staged, true, kBalance, 0, true, false},
    // The grid search reads the probe's samples.
    {Method::Oracle, "oracle", Split::Probed, true, kBalance, 0, true, false},
    // [TCE05]: a baseline outside MIS, what a real-time renderer would pick instead.
    {Method::Ris, "ris", Split::Fixed, false, Estimator::Resampled, 0, false, true},
};

constexpr bool inEnumOrder() {
  for (size_t i = 0; i < std::size(kMethods); ++i)
    if (size_t(kMethods[i].method) != i) return false;
  return true;
}
static_assert(inEnumOrder(), "methodTraits indexes kMethods by the enum");

std::string availableMethods() {
  std::vector<std::string> names;
  for (const auto& m : kMethods) names.push_back(m.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace

const MethodTraits& methodTraits(Method method) { return kMethods[size_t(method)]; }

const std::vector<Method>& allMethods() {
  static const std::vector<Method> methods = [] {
    std::vector<Method> out;
    for (const auto& m : kMethods) out.push_back(m.method);
    return out;
  }();
  return methods;
}

Method parseMethod(const std::string& name) {
  for (const auto& m : kMethods)
    if (name == m.name) return m.method;
  throw InputError(fmt::format("unknown --method '{}' (available: {})", name, availableMethods()));
}

std::string methodName(Method method) { return methodTraits(method).name; }

bool isAdaptive(Method method) { return methodTraits(method).adaptive(); }

std::vector<int> methodCounts(const Scene& scene, Method method, int spp, int pixel) {
  const int M = scene.techniqueCount();
  std::vector<int> counts(M, 0);
  switch (method) {
    case Method::Envmap:
    case Method::Ris:
      counts[0] = spp;
      break;
    case Method::Brdf:
      if (scene.options.techniqueRole(1) == kern::ROLE_BRDF) {
        counts[1] = spp;
      } else {  // the lobes, split
        const PhongParameters& p = scene.grid.pixels[pixel];
        double albedo = p.rhoD + p.rhoS;
        counts[1] = albedo > 0 ? int(std::lround(spp * p.rhoD / albedo)) : spp;
        // The specular lobe alone does not cover the diffuse lobe; the diffuse lobe
        // covers both (render/RunChecks.h).
        if (p.rhoD > 0) counts[1] = std::max(counts[1], 1);
        counts[2] = spp - counts[1];
      }
      break;
    default:
      for (int k = 0; k < M; ++k) counts[k] = spp / M + (k < spp % M ? 1 : 0);
      break;
  }
  return counts;
}

StagePlan singleStagePlan(const Scene& scene, Method method, int spp) {
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  StagePlan plan;
  plan.techniqueCount = M;
  plan.stageSamples = spp;
  plan.counts.reserve(size_t(pixels) * M);
  plan.firstIndex.assign(size_t(pixels) * M, 0u);
  for (int pixel = 0; pixel < pixels; ++pixel)
    for (int n : methodCounts(scene, method, spp, pixel)) plan.counts.push_back(n);
  leaveOutBackground(scene, plan.counts);
  return plan;
}

}  // namespace misalloc
