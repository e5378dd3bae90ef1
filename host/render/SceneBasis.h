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
  std::vector<double> costs;  // --cost as given; empty: each sampler's own (sampling/CostModel.h)
  std::string costSource;     // "calibrated" (on each sampler's launches) or "--cost"
};

struct SceneBasisRequest {
  bool findReference = true;  // the analytic, cached or computed reference (findReference)
  int referenceSpp = 16384;
  std::string cacheDir;
  bool needsCosts = false;         // some method allocates with costs
  std::vector<double> givenCosts;  // --cost, used as given; calibrated per sampler when empty
};

// The reference of `plainScene` (the scene with the plain envmap pdf: [Kar19]'s pdf
// changes the noise, not the integral, so one reference serves every pdf) and where the
// costs come from. `makeSampler` builds a sampler without statistics for the scene it
// is given, only where a reference is to be computed.
SceneBasis findSceneBasis(const Scene& plainScene, const SceneBasisRequest& request, const SamplerFactory& makeSampler);

}  // namespace misalloc
