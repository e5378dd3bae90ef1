#include "render/SceneBasis.h"

#include "sampling/Costs.h"

namespace misalloc {

SceneBasis findSceneBasis(const Scene& plainScene, const SceneBasisRequest& request, const SamplerFactory& makeSampler) {
  SceneBasis basis;
  if (request.findReference)
    basis.reference = findReference(plainScene, request.referenceSpp, request.cacheDir, makeSampler);
  if (!request.needsCosts) return basis;
  basis.costSource = request.givenCosts.empty() ? "measured" : "--cost";
  basis.costs = request.givenCosts.empty() ? measureCosts(*makeSampler(plainScene)) : request.givenCosts;
  return basis;
}

}  // namespace misalloc
