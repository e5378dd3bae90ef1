#include "render/Method.h"

#include <fmt/format.h>

#include <cmath>

#include "Error.h"
#include "KernelCode.h"

namespace misalloc {
namespace {

struct MethodName {
  Method method;
  const char* name;
};

constexpr MethodName kMethods[] = {
    {Method::Envmap, "envmap"},
    {Method::Brdf, "brdf"},
    {Method::Equal, "equal"},
    {Method::Heuristic, "heuristic"},
    {Method::SigmaSqrtC, "sigma-sqrt-c"},
    {Method::Linear, "linear"},
    {Method::Exact, "exact"},
    {Method::Oracle, "oracle"},
};

std::string availableMethods() {
  std::vector<std::string> names;
  for (const auto& m : kMethods) names.push_back(m.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

}  // namespace

const std::vector<Method>& allMethods() {
  static const std::vector<Method> methods{Method::Envmap,     Method::Brdf,   Method::Equal, Method::Heuristic,
                                           Method::SigmaSqrtC, Method::Linear, Method::Exact, Method::Oracle};
  return methods;
}

Method parseMethod(const std::string& name) {
  for (const auto& m : kMethods)
    if (name == m.name) return m.method;
  throw InputError(fmt::format("unknown --method '{}' (available: {})", name, availableMethods()));
}

std::string methodName(Method method) {
  for (const auto& m : kMethods)
    if (method == m.method) return m.name;
  return "?";
}

bool isAdaptive(Method method) { return method != Method::Envmap && method != Method::Brdf && method != Method::Equal; }

Estimator methodEstimator(Method method) {
  return method == Method::SigmaSqrtC ? Estimator::CountIndependent : Estimator::MultiSample;
}

unsigned methodStatistics(Method method) {
  switch (method) {
    case Method::Heuristic:
      return MA_STATS_TECHNIQUE;
    case Method::SigmaSqrtC:
      return MA_STATS_BALANCE;
    case Method::Linear:
      return MA_STATS_LINEAR;
    default:
      return 0;
  }
}

bool methodStoresSamples(Method method) {
  return method == Method::Linear || method == Method::Exact || method == Method::Oracle;
}

std::vector<int> methodCounts(const Scene& scene, Method method, int spp, int pixel) {
  const int M = scene.techniqueCount();
  std::vector<int> counts(M, 0);
  switch (method) {
    case Method::Envmap:
      counts[0] = spp;
      break;
    case Method::Brdf:
      if (M == 2) {
        counts[1] = spp;
      } else {
        const PhongParameters& p = scene.grid.pixels[pixel];
        double albedo = p.rhoD + p.rhoS;
        counts[1] = albedo > 0 ? int(std::lround(spp * p.rhoD / albedo)) : spp;
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
  return plan;
}

}  // namespace misalloc
