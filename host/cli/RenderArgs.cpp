#include "cli/RenderArgs.h"

#include <fmt/format.h>

#include <climits>

#include "Error.h"
#include "OptionRange.h"
#include "cli/StatisticsMemory.h"
#include "render/CostCache.h"
#include "render/RunChecks.h"
#include "report/ImageMetrics.h"
#include "report/Report.h"
#include "scene/ExrIO.h"

namespace misalloc {
namespace {

Estimator parseEstimator(const std::string& name) {
  if (name == "multi") return Estimator::MultiSample;
  if (name == "one") return Estimator::OneSample;
  throw InputError(fmt::format("--estimator '{}': expected multi or one", name));
}

}  // namespace

void RenderArgs::add(CLI::App& command) {
  scene.add(command);
  command.add_option("--cache-dir", cacheDir, "where references and the optimal pdf's tables are cached")
      ->capture_default_str()
      ->group("Scene");
  const size_t firstRenderOption = command.get_options().size();
  scene.addEnvmapPdf(command);
  command.add_option("--spp", spp, "samples per pixel")->capture_default_str()->check(integerIn(1, INT_MAX));
  command.add_option("--method", method, "envmap, brdf, equal, heuristic, sigma-sqrt-c, linear, exact, oracle or ris")
      ->capture_default_str();
  adaptive.add(command);
  command.add_option("--estimator", estimator, "fixed splits: multi ([HS14] eq. 4.1) or one (one-sample MIS)")
      ->capture_default_str();
  command
      .add_option("--weights", weights,
                  "MIS weights of the multi-sample stages: balance, or optimal ([Kon19], solved per pixel from the "
                  "stages before; equal then runs a --pilot first)")
      ->capture_default_str();
  command.add_option("--seed", seed, "random seed")->capture_default_str()->check(anyUnsigned64());
  devices.add(command,
              "comma-separated: auto, cpu, gpu, an index from `misalloc devices`, host (C++), all, or D:N "
              "(device D in N sub-devices)");
  command.add_option("--reference", reference, "auto (analytic, cached, or computed and cached), none, or an EXR path")
      ->capture_default_str();
  command.add_option("--reference-spp", referenceSpp, "spp of a sampled reference")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  command.add_option("--local-size", localSize, kLocalSizeHelp)->check(integerIn(1, INT_MAX));
  const auto options = command.get_options();
  for (size_t i = firstRenderOption; i < options.size(); ++i) options[i]->group("Render");
}

Method RenderArgs::resolveMethod() {
  const Method m = parseMethod(method);
  if (methodTraits(m).envmapOnly) scene.usePlainPdfByDefault();
  return m;
}

RenderPlan RenderArgs::plan(const Scene& s) const {
  const Method m = parseMethod(method);
  const Estimator e = parseEstimator(estimator);
  AdaptiveOptions options = adaptive.make(s.techniqueCount());
  options.weights = parseMisWeights(weights, "--weights");
  requireValidRun(s.options, m, e, spp, options);
  requireStatisticsMemory(s.options, {m}, "--spp", spp, options, devices.onHost(), devices.samplerCount());
  return {m, options, samplerConfigFor(m, e, spp, options, s.techniqueCount())};
}

std::optional<Reference> RenderArgs::referenceFile(const Scene& s) const {
  if (reference == "auto" || reference == "none") return std::nullopt;
  Reference file{readExr(reference), {}, "file", reference};
  checkSameSize(RgbImage{s.grid.width, s.grid.height, {}, {}}, file.image);
  return file;
}

RenderOutcome RenderArgs::render(const Scene& sampled, const Scene& plainScene, RenderPlan& plan,
                                 std::optional<Reference> given) {
  RenderOutcome out;
  auto sampler = devices.makeSampler(sampled, plan.config, localSize);
  out.deviceName = devices.name();
  if (!given && reference == "auto")
    given = findReference(plainScene, referenceSpp, cacheDir,
                          [&](const Scene& r) { return devices.makeSampler(r, SamplerConfig{}, localSize); });
  out.reference = std::move(given);
  if (methodTraits(plan.method).adaptive() && plan.adaptive.costs.empty())
    provideCostModel(*sampler, plainScene, {cacheDir, plan.adaptive.measureCosts});
  out.rendering = misalloc::render(*sampler, plan.method, plan.adaptive, spp, seed);
  return out;
}

nlohmann::json RenderArgs::report(const Scene& s, const RenderPlan& plan, const RenderOutcome& outcome) const {
  return renderReport({s, plan.method, plan.config.estimator, plan.adaptive, spp, seed, outcome.deviceName,
                       outcome.rendering, outcome.reference});
}

}  // namespace misalloc
