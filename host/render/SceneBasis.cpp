#include "render/SceneBasis.h"


namespace misalloc {

SceneBasis findSceneBasis(const Scene& plainScene, const SceneBasisRequest& request, const SamplerFactory& makeSampler) {
  SceneBasis basis;
  if (request.findReference)
    basis.reference = findReference(plainScene, request.referenceSpp, request.cacheDir, makeSampler);
  if (!request.needsCosts) return basis;
  basis.costSource = request.givenCosts.empty() ? "calibrated" : "--cost";
  basis.costs = request.givenCosts;
  return basis;
}

}  // namespace misalloc
