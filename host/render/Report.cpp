#include "render/Report.h"

#include <cmath>

#include "render/ImageMetrics.h"

namespace misalloc {

nlohmann::json sceneJson(const Scene& scene) {
  const SceneOptions& o = scene.options;
  return {{"envmap", o.envmap},
          {"envmap_file", scene.envmapPath},
          {"envmap_size", {scene.tables.width, scene.tables.height}},
          {"envmap_uniform_fallback", scene.tables.uniformFallback},
          {"grid", o.grid},
          {"size", {o.width, o.height}},
          {"view_deg", {o.viewTheta, o.viewPhi}},
          {"techniques", scene.techniqueNames()},
          {"envmap_sampler", scene.tables.useCdf ? "cdf" : "alias"}};
}

nlohmann::json renderReport(const RenderRun& run) {
  const Rendering& r = run.rendering;
  double meanVariance = 0;
  for (double v : r.variance) meanVariance += v;
  meanVariance /= double(r.variance.size());
  nlohmann::json report = {
      {"scene", sceneJson(run.scene)},
      {"method", methodName(run.method)},
      {"estimator", run.estimator == Estimator::OneSample ? "one-sample" : "multi-sample"},
      {"spp", run.spp},
      {"seed", run.seed},
      {"device", run.device},
      {"time_s", {{"wall", r.wallSeconds}, {"kernel", r.kernelSeconds}, {"host", r.hostSeconds}}},
      {"samples_per_second", double(run.scene.pixelCount()) * run.spp / r.kernelSeconds},
      {"estimated_rmse_luminance_x1000", 1000 * std::sqrt(meanVariance)},
  };
  if (run.reference) {
    report["reference"] = {{"source", run.reference->source}, {"path", run.reference->path}};
    report["rmse_x1000"] = 1000 * rmse(r.image, run.reference->image);
    report["relative_mse"] = relativeMse(r.image, run.reference->image);
  } else {
    report["reference"] = nullptr;
  }
  return report;
}

}  // namespace misalloc
