#pragma once
// The options of a render and the render they ask for, without its files: `misalloc
// render` writes the result, the Python module hands it over as arrays. One list of
// options and defaults serves both.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cli/AdaptiveArgs.h"
#include "cli/DeviceArgs.h"
#include "cli/SceneArgs.h"
#include "render/Reference.h"
#include "render/Render.h"

namespace misalloc {

// What the options ask of one scene, resolved and checked before any work.
struct RenderPlan {
  Method method;
  AdaptiveOptions adaptive;
  SamplerConfig config;
};

// A finished render and what it was judged and allocated with.
struct RenderOutcome {
  Rendering rendering;
  std::optional<Reference> reference;
  std::string deviceName;
};

struct RenderArgs {
  SceneArgs scene;
  AdaptiveArgs adaptive;
  DeviceArgs devices;
  int spp = 200, localSize = kDefaultLocalSize, referenceSpp = 16384;
  uint64_t seed = 1;
  std::string method = "exact", estimator = "multi", weights = "balance", reference = "auto",
              cacheDir = defaultCacheDir();

  // The scene's options, --cache-dir among them (option group "Scene"), and the render's
  // ("Render").
  void add(CLI::App& command);

  // --method parsed; envmap sampling alone then takes the plain pdf by default (the
  // optimal one does not cover f alone). Call before the scene is made.
  Method resolveMethod();
  // The options checked against `scene` (whole, not a band), before any work.
  RenderPlan plan(const Scene& scene) const;
  // --reference read where it names a file; none for auto and none.
  std::optional<Reference> referenceFile(const Scene& scene) const;
  // Renders `sampled` (the scene, or a band's rows of it) after finding the reference
  // of `plainScene` (unless `given`), the whole scene with the plain pdf
  // (withPlainEnvmapPdf): [Kar19]'s pdf changes the noise, not the integral, so one
  // reference serves every pdf. An adaptive method without --cost allocates with the
  // cost cache's model of its sampler for the whole image (render/CostCache.h).
  RenderOutcome render(const Scene& sampled, const Scene& plainScene, RenderPlan& plan, std::optional<Reference> given);
  // The JSON report of `outcome`, a render of `scene` planned by `plan`.
  nlohmann::json report(const Scene& scene, const RenderPlan& plan, const RenderOutcome& outcome) const;
};

}  // namespace misalloc
