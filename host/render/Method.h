#pragma once
#include <string>
#include <vector>

#include "render/Scene.h"
#include "render/Stage.h"

namespace misalloc {

// How a pixel's N samples are split among the techniques.
enum class Method { Envmap, Brdf, Equal };

// Throws InputError for an unknown name, and for the allocations that are not
// implemented yet (heuristic, sigma-sqrt-c, linear, exact, oracle).
Method parseMethod(const std::string& name);
std::string methodName(Method method);

// Counts n_k for one pixel, Σ_k n_k = spp. Single-technique methods give the others 0;
// with the BRDF split into lobes, `brdf` shares its samples by the lobes' albedos.
std::vector<int> methodCounts(const Scene& scene, Method method, int spp, int pixel);

// One stage of `spp` samples per pixel with the method's counts.
StagePlan singleStagePlan(const Scene& scene, Method method, int spp);

}  // namespace misalloc
