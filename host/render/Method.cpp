#include "render/Method.h"

#include <fmt/format.h>

#include <cmath>

#include "Error.h"

namespace misalloc {

Method parseMethod(const std::string& name) {
  if (name == "envmap") return Method::Envmap;
  if (name == "brdf") return Method::Brdf;
  if (name == "equal") return Method::Equal;
  for (const char* planned : {"heuristic", "sigma-sqrt-c", "linear", "exact", "oracle"})
    if (name == planned)
      throw InputError(fmt::format("--method {}: this allocation is not implemented yet (available: envmap, brdf, equal)",
                                   name));
  throw InputError(fmt::format("unknown --method '{}' (available: envmap, brdf, equal)", name));
}

std::string methodName(Method method) {
  switch (method) {
    case Method::Envmap: return "envmap";
    case Method::Brdf: return "brdf";
    case Method::Equal: return "equal";
  }
  return "?";
}

std::vector<int> methodCounts(const Scene& scene, Method method, int spp, int pixel) {
  const int M = scene.techniqueCount();
  std::vector<int> counts(M, 0);
  switch (method) {
    case Method::Envmap: counts[0] = spp; break;
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
    case Method::Equal:
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
