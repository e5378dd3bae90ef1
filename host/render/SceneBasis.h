#pragma once
// What the renders of one scene are judged and allocated with, found once per scene,
// before the first render, by render and by compare alike.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "render/Reference.h"
#include "sampling/StageSampler.h"

namespace misalloc {

struct SceneBasis {
  std::optional<Reference> reference;
  std::vector<double> costs;  // c_k per sample; empty where no method allocates
  std::string costSource;     // "measured" or "--cost"
};

struct SceneBasisRequest {
  bool findReference = true;  // the analytic, cached or computed reference (findReference)
  int referenceSpp = 16384;
  std::string cacheDir;
  bool needsCosts = false;         // some method allocates with costs
  std::vector<double> givenCosts;  // --cost, used as given; measured when empty
};

// The reference and the costs of `plainScene` (the scene with the plain envmap pdf:
// [Kar19]'s pdf changes the noise, not the integral, so one reference and one cost
// measurement serve every pdf). `makeSampler` builds a sampler without statistics for
// the scene it is given, only where one is needed (a reference to compute, costs to
// measure).
SceneBasis findSceneBasis(const Scene& plainScene, const SceneBasisRequest& request, const SamplerFactory& makeSampler);

}  // namespace misalloc
