// misalloc reference: a converged reference image, found in the cache or computed and
// cached.
#include <fmt/format.h>

#include <climits>
#include <iostream>
#include <memory>

#include "Interruption.h"
#include "OptionRange.h"
#include "OutputSet.h"
#include "cli/DeviceArgs.h"
#include "cli/SceneArgs.h"
#include "cli/SceneInputs.h"
#include "cli/Subcommand.h"
#include "render/Reference.h"
#include "scene/ExrIO.h"

namespace misalloc {
namespace {

struct ReferenceArgs {
  SceneArgs scene;
  DeviceArgs devices;
  int spp = 16384;
  std::string cacheDir = defaultCacheDir(), out;
};

int runReference(ReferenceArgs& args) {
  exitOnInterrupt();
  OutputSet outputs(sceneInputs({args.scene.parsed()}));
  if (!args.out.empty()) outputs.claim("--out", args.out);
  args.scene.options.bankCacheDir = args.cacheDir;
  Scene scene = args.scene.make();
  if (auto cached = referenceCachePath(scene, args.spp, args.cacheDir))
    outputs.addInput({"the cached reference (--cache-dir)", *cached});
  Reference reference = findReference(scene, args.spp, args.cacheDir, [&](const Scene& s) {
    return args.devices.makeSampler(s, SamplerConfig{}, kDefaultLocalSize);
  });
  if (!args.out.empty()) outputs.put(args.out, encodeExr(reference.image));
  outputs.commit();
  cacheOptimalBank(scene);
  std::cout << fmt::format("reference: {}{}\n", reference.source,
                           reference.path.empty() ? "" : " at " + reference.path);
  return 0;
}

}  // namespace

Subcommand addReferenceCommand(CLI::App& app) {
  auto* command = app.add_subcommand("reference", "compute (or find in the cache) a converged reference image");
  auto args = std::make_shared<ReferenceArgs>();
  args->scene.add(*command);
  command->add_option("--spp", args->spp, "samples per pixel")->capture_default_str()->check(integerIn(1, INT_MAX));
  args->devices.add(*command, "comma-separated: auto, cpu, gpu, index, host, all or D:N");
  command->add_option("--cache-dir", args->cacheDir, "where references and the optimal pdf's tables are cached")
      ->capture_default_str();
  command->add_option("--out", args->out, "also write the reference to this EXR");
  return {command, [args] { return runReference(*args); }};
}

}  // namespace misalloc
