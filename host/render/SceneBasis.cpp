#include "render/SceneBasis.h"

#include "sampling/Costs.h"

namespace misalloc {

SceneBasis findSceneBasis(const Scene& plainScene, const SceneBasisRequest& request,
                          const std::function<std::unique_ptr<StageSampler>()>& makePlainSampler) {
  std::unique_ptr<StageSampler> plain;
  auto plainSampler = [&]() -> StageSampler& {
    if (!plain) plain = makePlainSampler();
    return *plain;
  };
  SceneBasis basis;
  if (request.findReference)
    basis.reference = findReference(plainScene, request.referenceSpp, request.cacheDir, plainSampler);
  if (!request.needsCosts) return basis;
  basis.costSource = request.givenCosts.empty() ? "measured" : "--cost";
  basis.costs = request.givenCosts.empty() ? measureCosts(plainSampler()) : request.givenCosts;
  return basis;
}

}  // namespace misalloc
