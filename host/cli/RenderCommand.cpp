// misalloc render: one scene with one method, its image, report and α map, and its
// error against a reference.
#include <fmt/format.h>

#include <climits>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>

#include "Error.h"
#include "Interruption.h"
#include "JsonText.h"
#include "OptionRange.h"
#include "OutputSet.h"
#include "cli/AdaptiveArgs.h"
#include "cli/DeviceArgs.h"
#include "cli/RunIdentity.h"
#include "cli/SceneArgs.h"
#include "cli/SceneInputs.h"
#include "cli/StatisticsMemory.h"
#include "cli/Subcommand.h"
#include "render/Band.h"
#include "render/BandFile.h"
#include "render/Method.h"
#include "render/Reference.h"
#include "render/Render.h"
#include "render/RunChecks.h"
#include "render/SceneBasis.h"
#include "report/AlphaMap.h"
#include "report/ImageMetrics.h"
#include "report/PreviewPng.h"
#include "report/Report.h"
#include "scene/ExrIO.h"

namespace misalloc {
namespace {

struct RenderArgs {
  SceneArgs scene;
  AdaptiveArgs adaptive;
  DeviceArgs devices;
  int spp = 200, localSize = kDefaultLocalSize, referenceSpp = 16384;
  uint64_t seed = 1;
  bool noPreview = false;
  std::string method = "exact", estimator = "multi", weights = "balance", out = "render.exr", report = "render.json",
              reference = "auto", cacheDir = defaultCacheDir(), alphaMap, shard;
  std::function<std::string()> run;  // the run's identity (cli/RunIdentity.h), for a sharded render's bands
};

// A band of a sharded render writes its rows only: no preview, no α map.
void refuseBandOutputs(RenderArgs& args) {
  if (args.shard.empty()) return;
  if (!args.alphaMap.empty()) throw InputError("--alpha-map: a band of a sharded render (--shard) writes no alpha map");
  args.noPreview = true;
}

// A sharded render's band (render/Band.h) and where its costs come from, checked before
// any work.
std::optional<Band> requestedBand(const RenderArgs& args, Method m, const AdaptiveOptions& adaptive, int height) {
  if (args.shard.empty()) return std::nullopt;
  // Costs measured by each band on its own node would differ, and so would the bands'
  // allocations: a seam. Every band takes the same costs.
  if (methodTraits(m).adaptive() && adaptive.costs.empty())
    throw InputError(
        fmt::format("--shard with --method {}: give the costs with --cost (every band must allocate with "
                    "the same costs; a render's report has them as costs_s_per_sample)",
                    args.method));
  return bandOf(parseShard(args.shard, "--shard"), height, poolingHaloRows(m, adaptive));
}

Estimator parseEstimator(const std::string& name) {
  if (name == "multi") return Estimator::MultiSample;
  if (name == "one") return Estimator::OneSample;
  throw InputError(fmt::format("--estimator '{}': expected multi or one", name));
}

int runRender(RenderArgs& args) {
  exitOnInterrupt();
  const Method m = parseMethod(args.method);
  const MethodTraits& traits = methodTraits(m);
  const Estimator estimator = parseEstimator(args.estimator);
  if (traits.envmapOnly) args.scene.usePlainPdfByDefault();  // the optimal pdf does not cover f alone
  std::vector<NamedFile> inputs = sceneInputs({args.scene.parsed()});
  if (args.reference != "auto" && args.reference != "none") inputs.push_back({"--reference", args.reference});
  OutputSet outputs(inputs);
  outputs.claim("--out", args.out);
  outputs.claim("--report", args.report);
  refuseBandOutputs(args);
  if (!args.noPreview) outputs.claim("the preview (--no-preview skips it)", previewPath(args.out));
  if (!args.alphaMap.empty()) {
    outputs.claim("--alpha-map", args.alphaMap);
    outputs.claim("--alpha-map", alphaPngPath(args.alphaMap));
  }
  args.scene.options.bankCacheDir = args.cacheDir;
  Scene scene = args.scene.make();
  AdaptiveOptions adaptive = args.adaptive.make(scene.techniqueCount());
  adaptive.weights = parseMisWeights(args.weights, "--weights");
  requireValidRun(scene.options, m, estimator, args.spp, adaptive);
  const std::optional<Band> band = requestedBand(args, m, adaptive, scene.grid.height);
  SamplerConfig config = samplerConfigFor(m, estimator, args.spp, adaptive);
  requireStatisticsMemory(scene.options, {m}, "--spp", args.spp, adaptive, args.devices.onHost(),
                          args.devices.samplerCount());
  // The reference's key and the costs do not depend on the pdf ([Kar19]: it changes the
  // noise, not the integral): one lookup and one measurement serve every pdf.
  const Scene plainScene = withPlainEnvmapPdf(scene);
  std::optional<Reference> reference;
  if (args.reference == "auto") {
    if (auto cached = referenceCachePath(plainScene, args.referenceSpp, args.cacheDir))
      outputs.addInput({"the cached reference (--cache-dir)", *cached});
  } else if (args.reference != "none") {
    reference = Reference{readExr(args.reference), {}, "file", args.reference};
    checkSameSize(RgbImage{scene.grid.width, scene.grid.height, {}, {}}, reference->image);
  }
  // A band renders its rows and those its pooling reads, with the image's random numbers.
  std::optional<Scene> bandRows;
  if (band) bandRows = bandScene(scene, band->rendered);
  auto sampler = args.devices.makeSampler(band ? *bandRows : scene, config, args.localSize);
  std::string deviceName = args.devices.name();
  SceneBasis basis = findSceneBasis(
      plainScene, {args.reference == "auto", args.referenceSpp, args.cacheDir, traits.adaptive(), adaptive.costs},
      [&](const Scene& s) { return args.devices.makeSampler(s, SamplerConfig{}, args.localSize); });
  if (basis.reference) reference = std::move(basis.reference);
  adaptive.costs = basis.costs;
  Rendering r = render(*sampler, m, adaptive, args.spp, args.seed);
  const int width = scene.grid.width, height = scene.grid.height;
  if (band) {
    // The band's report is of its own rows, as a scene of their own.
    r = cropRendering(r, width, scene.techniqueCount(), band->rendered, band->rows);
    if (reference) reference = cropReference(*reference, band->rows);
    scene = bandScene(std::move(scene), band->rows);
  }
  nlohmann::json report = renderReport(
      {scene, m, config.estimator, adaptive, basis.costSource, args.spp, args.seed, deviceName, r, reference});
  if (band) {
    report["band"] = {{"shard", args.shard},
                      {"rows", {band->rows.begin, band->rows.end}},
                      {"rendered_rows", {band->rendered.begin, band->rendered.end}}};
    outputs.put(args.out, encodeBand(r.image, {args.run(), *band, width, height, nodeName(), report}));
  } else {
    outputs.put(args.out, encodeExr(r.image));
  }
  if (!args.noPreview)
    outputs.put(previewPath(args.out),
                encodePreviewPng(r.image, previewExposure(reference ? reference->image : r.image)));
  if (!args.alphaMap.empty()) {
    AlphaMapFiles alpha = encodeAlphaMaps(scene, r);
    outputs.put(args.alphaMap, std::move(alpha.exr));
    outputs.put(alphaPngPath(args.alphaMap), std::move(alpha.png));
  }
  outputs.put(args.report, jsonText(report));
  outputs.commit();
  cacheOptimalBank(scene);
  std::cout << fmt::format("{} | {} x {} | {}x{} | {} spp | {} | {:.3f} s (kernel {:.3f} s, allocation {:.3f} s)\n",
                           deviceName, scene.options.envmap, scene.options.grid, scene.grid.width, scene.grid.height,
                           args.spp, traits.name, r.wallSeconds, r.kernelSeconds, r.allocationSeconds);
  if (reference)
    std::cout << fmt::format(
        "RMSE x1000 {:.3f}, {:.3f} corrected for the reference's own error, relative MSE {:.4g} (reference: {})\n",
        report["rmse_x1000"].get<double>(), report["rmse_x1000_corrected"].get<double>(),
        report["relative_mse"].get<double>(), reference->source);
  std::cout << fmt::format(
      "wrote {}{}, {}{}\n", args.out, args.noPreview ? "" : ", " + previewPath(args.out), args.report,
      args.alphaMap.empty() ? "" : fmt::format(", {} and {}", args.alphaMap, alphaPngPath(args.alphaMap)));
  return 0;
}

}  // namespace

Subcommand addRenderCommand(CLI::App& app) {
  auto* command = app.add_subcommand("render", "render a scene (default: forest_slope x seed000, 128x128, 200 spp)");
  auto args = std::make_shared<RenderArgs>();
  args->scene.add(*command);
  args->scene.addEnvmapPdf(*command);
  command->add_option("--spp", args->spp, "samples per pixel")->capture_default_str()->check(integerIn(1, INT_MAX));
  command
      ->add_option("--method", args->method,
                   "envmap, brdf, equal, heuristic, sigma-sqrt-c, linear, exact, oracle or ris")
      ->capture_default_str();
  args->adaptive.add(*command);
  command->add_option("--alpha-map", args->alphaMap,
                      "write the per-pixel allocation: EXR here, false-colour PNG beside");
  command->add_option("--estimator", args->estimator, "fixed splits: multi ([HS14] eq. 4.1) or one (one-sample MIS)")
      ->capture_default_str();
  command
      ->add_option("--weights", args->weights,
                   "MIS weights of the multi-sample stages: balance, or optimal ([Kon19], solved per pixel from the "
                   "stages before; equal then runs a --pilot first)")
      ->capture_default_str();
  command->add_option("--seed", args->seed, "random seed")->capture_default_str()->check(anyUnsigned64());
  args->devices.add(*command,
                    "comma-separated: auto, cpu, gpu, an index from `misalloc devices`, host (C++), all, or D:N "
                    "(device D in N sub-devices)");
  command->add_option("--out", args->out, "output EXR")->capture_default_str();
  command->add_option("--report", args->report, "output JSON report")->capture_default_str();
  command->add_flag("--no-preview", args->noPreview, "write no PNG preview beside the EXR (--out with .png)");
  command
      ->add_option("--reference", args->reference,
                   "auto (analytic, cached, or computed and cached), none, or an EXR path")
      ->capture_default_str();
  command->add_option("--reference-spp", args->referenceSpp, "spp of a sampled reference")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  command->add_option("--cache-dir", args->cacheDir, "where references and the optimal pdf's tables are cached")
      ->capture_default_str();
  command->add_option("--local-size", args->localSize, kLocalSizeHelp)->check(integerIn(1, INT_MAX));
  command->add_option("--shard", args->shard,
                      "K/N: render band K of N (whole rows of 16-pixel blocks) into --out, for `misalloc merge`");
  return {command, [args, command] {
            // Once runRender has resolved the scene's options and read its inputs.
            args->run = [command, scene = &args->scene] {
              return runIdentity(*command,
                                 {"--shard", "--out", "--report", "--no-preview", "--cache-dir", "--reference",
                                  "--reference-spp", "--help"},
                                 {scene->options});
            };
            return runRender(*args);
          }};
}

}  // namespace misalloc
