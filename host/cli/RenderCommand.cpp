// misalloc render: one scene with one method, its image, report and α map, and its
// error against a reference.
#include <fmt/format.h>

#include <functional>
#include <iostream>
#include <memory>
#include <optional>

#include "Error.h"
#include "Interruption.h"
#include "JsonText.h"
#include "OutputSet.h"
#include "cli/RenderArgs.h"
#include "cli/RunIdentity.h"
#include "cli/SceneInputs.h"
#include "cli/Subcommand.h"
#include "render/Band.h"
#include "render/BandFile.h"
#include "render/Method.h"
#include "render/Reference.h"
#include "render/Render.h"
#include "report/AlphaMap.h"
#include "report/ImageMetrics.h"
#include "report/PreviewPng.h"
#include "scene/ExrIO.h"

namespace misalloc {
namespace {

// The render's options and its files: the EXR, the report, the preview, the α map, a
// sharded render's band.
struct RenderCommandArgs {
  RenderArgs render;
  bool noPreview = false;
  std::string out = "render.exr", report = "render.json", alphaMap, shard;
  std::function<std::string()> run;  // the run's identity (cli/RunIdentity.h), for a sharded render's bands
};

// A band of a sharded render writes its rows only: no preview, no α map.
void refuseBandOutputs(RenderCommandArgs& args) {
  if (args.shard.empty()) return;
  if (!args.alphaMap.empty()) throw InputError("--alpha-map: a band of a sharded render (--shard) writes no alpha map");
  args.noPreview = true;
}

// A sharded render's band (render/Band.h), checked before any work. exact's whole-image
// rule decides from every pixel's pilot, which a band does not see: bands that decided
// apart would not merge into the unsharded image.
std::optional<Band> requestedBand(const RenderCommandArgs& args, const RenderPlan& plan, int height) {
  if (args.shard.empty()) return std::nullopt;
  Band band = bandOf(parseShard(args.shard, "--shard"), height, poolingHaloRows(plan.method, plan.adaptive));
  if (plan.method == Method::Exact && plan.adaptive.imageGainBelow > 0)
    throw InputError(fmt::format(
        "--shard with --method exact: the whole-image rule (--skip-image-below {}) decides from the whole image's "
        "pilot, which a band does not see; give --skip-image-below 0 (the rule off) to every band and to the "
        "unsharded render they are compared with",
        plan.adaptive.imageGainBelow));
  return band;
}

// A band's run identity: the run's, and the costs it allocated with. Bands that share a
// cost cache take one calibration (render/CostCache.h); bands calibrated apart (nodes of
// other devices, or caches not shared) allocate differently, and their merge is refused.
std::string bandIdentity(const std::string& run, const Rendering& r) {
  if (!r.costModel) return run;
  return fmt::format("{}; costs {} (statistics kernel {})", run, fmt::join(r.costModel->perSample(false), ","),
                     fmt::join(r.costModel->perSample(true), ","));
}

int runRender(RenderCommandArgs& args) {
  exitOnInterrupt();
  RenderArgs& ra = args.render;
  const MethodTraits& traits = methodTraits(ra.resolveMethod());
  std::vector<NamedFile> inputs = sceneInputs({ra.scene.parsed()});
  if (ra.reference != "auto" && ra.reference != "none") inputs.push_back({"--reference", ra.reference});
  OutputSet outputs(inputs);
  outputs.claim("--out", args.out);
  outputs.claim("--report", args.report);
  refuseBandOutputs(args);
  if (!args.noPreview) outputs.claim("the preview (--no-preview skips it)", previewPath(args.out));
  if (!args.alphaMap.empty()) {
    outputs.claim("--alpha-map", args.alphaMap);
    outputs.claim("--alpha-map", alphaPngPath(args.alphaMap));
  }
  ra.scene.options.bankCacheDir = ra.cacheDir;
  Scene scene = ra.scene.make();
  RenderPlan plan = ra.plan(scene);
  const std::optional<Band> band = requestedBand(args, plan, scene.grid.height);
  const Scene plainScene = withPlainEnvmapPdf(scene);
  if (ra.reference == "auto")
    if (auto cached = referenceCachePath(plainScene, ra.referenceSpp, ra.cacheDir))
      outputs.addInput({"the cached reference (--cache-dir)", *cached});
  std::optional<Reference> given = ra.referenceFile(scene);
  // A band renders its rows and those its pooling reads, with the image's random numbers.
  std::optional<Scene> bandRows;
  if (band) bandRows = bandScene(scene, band->rendered);
  RenderOutcome outcome = ra.render(band ? *bandRows : scene, plainScene, plan, std::move(given));
  Rendering& r = outcome.rendering;
  std::optional<Reference>& reference = outcome.reference;
  const int width = scene.grid.width, height = scene.grid.height;
  if (band) {
    // The band's report is of its own rows, as a scene of their own.
    r = cropRendering(r, width, scene.techniqueCount(), band->rendered, band->rows);
    if (reference) reference = cropReference(*reference, band->rows);
    scene = bandScene(std::move(scene), band->rows);
  }
  nlohmann::json report = ra.report(scene, plan, outcome);
  if (band) {
    report["band"] = {{"shard", args.shard},
                      {"rows", {band->rows.begin, band->rows.end}},
                      {"rendered_rows", {band->rendered.begin, band->rendered.end}}};
    outputs.put(args.out, encodeBand(r.image, {bandIdentity(args.run(), r), *band, width, height, nodeName(), report}));
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
                           outcome.deviceName, scene.options.envmap, scene.options.grid, scene.grid.width,
                           scene.grid.height, ra.spp, traits.name, r.wallSeconds, r.kernelSeconds, r.allocationSeconds);
  if (r.keptEqualCounts)
    std::cout << fmt::format(
        "kept equal counts after the pilot: it predicted a gain of {:.3f} over them at equal time, below "
        "--skip-image-below {:g}\n",
        *r.predictedGain, plan.adaptive.imageGainBelow);
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
  auto args = std::make_shared<RenderCommandArgs>();
  args->render.add(*command);
  command->add_option("--out", args->out, "output EXR")->capture_default_str()->group("Outputs");
  command->add_option("--report", args->report, "output JSON report")->capture_default_str()->group("Outputs");
  command->add_flag("--no-preview", args->noPreview, "write no PNG preview beside the EXR (--out with .png)")
      ->group("Outputs");
  command
      ->add_option("--alpha-map", args->alphaMap, "write the per-pixel allocation: EXR here, false-colour PNG beside")
      ->group("Outputs");
  command
      ->add_option("--shard", args->shard,
                   "K/N: render band K of N (whole rows of 16-pixel blocks) into --out, for `misalloc merge`")
      ->group("Outputs");
  return {command, [args, command] {
            // Once runRender has resolved the scene's options and read its inputs.
            args->run = [command, scene = &args->render.scene] {
              return runIdentity(*command,
                                 {"--shard", "--out", "--report", "--no-preview", "--cache-dir", "--reference",
                                  "--reference-spp", "--help"},
                                 {scene->options});
            };
            return runRender(*args);
          }};
}

}  // namespace misalloc
