#pragma once
#include <string>
#include <vector>

#include "sampling/Stage.h"
#include "scene/Scene.h"

namespace misalloc {

// How a pixel's N samples are split among the techniques. What each method is, which
// estimator and statistics it needs, and how its α is found, is one row of the table in
// Method.cpp (methodTraits).
enum class Method { Envmap, Brdf, Equal, Heuristic, SigmaSqrtC, Linear, Exact, Oracle, Ris };

// Where a method's split comes from.
enum class Split {
  // The method's own counts (methodCounts), in one stage.
  Fixed,
  // A pilot, then stages, each split by the α of the samples before it (render/Render.h).
  Staged,
  // Evaluation only: the α that a probe of samples beyond the budget finds best, then one
  // stage; a bound on what allocation can reach, not a contender.
  Probed,
};

struct MethodTraits {
  Method method;
  const char* name;
  Split split;
  // α from the grid search over U weight combinations (alloc/GridSearch.h, [HS14]
  // Algorithm 1); an adaptive method without it has a per-pixel rule from its running
  // sums or samples (alloc/).
  bool searchesWeights;
  // The estimator of an adaptive method's stages: σ/√c allocates for the estimator with
  // count-independent weights ([SHS16] Sec. 4), everything else for the balance
  // heuristic. `ris` is an estimator of its own ([TCE05]). The other fixed splits take
  // the estimator asked for.
  Estimator estimator;
  unsigned statistics;  // the running sums each pixel keeps (kernels/stats.h)
  bool storesSamples;   // and the samples themselves
  // Samples from the envmap pdf alone, which must then cover the integrand: the plain
  // pdf only (render/RunChecks.h).
  bool envmapOnly;

  constexpr bool adaptive() const { return split != Split::Fixed; }
  // Whether the method's estimator is its own rather than the one asked for.
  constexpr bool fixesEstimator() const { return adaptive() || estimator == Estimator::Resampled; }
};

const MethodTraits& methodTraits(Method method);

// Every method, in the order of the tables ([HS14] Table 5.2's rows, then ours).
const std::vector<Method>& allMethods();

// Throws InputError for an unknown name.
Method parseMethod(const std::string& name);
std::string methodName(Method method);
bool isAdaptive(Method method);

// Counts n_k for one pixel of a fixed split, Σ_k n_k = spp. Single-technique methods
// (`ris` resamples the envmap technique's samples) give the others 0; with the BRDF
// split into lobes, `brdf` shares its samples by the lobes' albedos.
std::vector<int> methodCounts(const Scene& scene, Method method, int spp, int pixel);

// One stage of `spp` samples per pixel with a fixed split's counts.
StagePlan singleStagePlan(const Scene& scene, Method method, int spp);

}  // namespace misalloc
