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
  const AdaptiveOptions& adaptive;
  int spp;
  uint64_t seed;
  std::string device;
  const Rendering& rendering;
  const std::optional<Reference>& reference;
};

// The JSON report of one render: scene, method, spp, device, wall time split into
// kernel, allocation and host time, the allocation's schedule, costs, mean α and
// defensive-rule counts, and the errors against the reference when there is one.
nlohmann::json renderReport(const RenderRun& run);
// Each stage's kernel time and, for the adaptive methods, the cost model's prediction.
nlohmann::json stagesJson(const std::vector<StageTiming>& stages);
// The fitted (or given) costs of both kernels, and where they came from.
nlohmann::json costModelJson(const CostModel& model, const std::vector<std::string>& techniqueNames);

nlohmann::json sceneJson(const Scene& scene);

// The "time_s" object of every report: wall seconds split into sampling kernels,
// allocation and host work.
nlohmann::json timeSplitJson(double wall, double kernel, double allocation, double host);

std::string estimatorName(Estimator estimator);

}  // namespace misalloc
