#pragma once
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "render/Method.h"
#include "render/Reference.h"
#include "render/Render.h"

namespace misalloc {

struct RenderRun {
  const Scene& scene;
  Method method;
  Estimator estimator;
  int spp;
  uint64_t seed;
  std::string device;
  const Rendering& rendering;
  const std::optional<Reference>& reference;
};

// The JSON report of one render: scene, method, spp, device, wall time split into
// kernel and host time, and the errors against the reference when there is one.
nlohmann::json renderReport(const RenderRun& run);

nlohmann::json sceneJson(const Scene& scene);

}  // namespace misalloc
