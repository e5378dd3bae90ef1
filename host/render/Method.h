#pragma once
#include <string>
#include <vector>

#include "render/Scene.h"
#include "render/Stage.h"

namespace misalloc {

// How a pixel's N samples are split among the techniques. The first three are fixed
// splits taken in one stage; heuristic, sigma-sqrt-c, linear and exact allocate
// adaptively in batches; oracle (evaluation only) takes the α that a high-sample
// probe finds best (render/Render.h).
enum class Method { Envmap, Brdf, Equal, Heuristic, SigmaSqrtC, Linear, Exact, Oracle };

// Every method, in the order of the tables ([HS14] Table 5.2's rows, then ours).
const std::vector<Method>& allMethods();

// Throws InputError for an unknown name.
Method parseMethod(const std::string& name);
std::string methodName(Method method);
bool isAdaptive(Method method);

// The estimator each method's stages use: σ/√c allocates for the estimator with
// count-independent weights ([SHS16] Sec. 4); everything else for the balance heuristic.
Estimator methodEstimator(Method method);

// The running sums (kernels/stats.h) and whether the stored samples are needed.
unsigned methodStatistics(Method method);
bool methodStoresSamples(Method method);

// Counts n_k for one pixel of a fixed split, Σ_k n_k = spp. Single-technique methods
// give the others 0; with the BRDF split into lobes, `brdf` shares its samples by
// the lobes' albedos.
std::vector<int> methodCounts(const Scene& scene, Method method, int spp, int pixel);

// One stage of `spp` samples per pixel with a fixed split's counts.
StagePlan singleStagePlan(const Scene& scene, Method method, int spp);

}  // namespace misalloc
