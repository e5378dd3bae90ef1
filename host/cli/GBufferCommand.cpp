// misalloc gbuffer: what a scene's pixels see, written as a G-buffer, so that a user can
// look at what is rendered, and render it again with --gbuffer.
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "Interruption.h"
#include "OutputSet.h"
#include "cli/SceneArgs.h"
#include "cli/SceneInputs.h"
#include "cli/Subcommand.h"
#include "scene/GBuffer.h"

namespace misalloc {
namespace {

struct GBufferArgs {
  SceneArgs scene;
  std::string out = "gbuffer.exr";
};

int runGBuffer(GBufferArgs& args) {
  exitOnInterrupt();
  OutputSet outputs(sceneInputs({args.scene.parsed()}));
  outputs.claim("--out", args.out);
  const Scene scene = args.scene.make();
  outputs.put(args.out, encodeGBuffer(scene.grid.width, scene.grid.height, scene.geometry, scene.grid.pixels));
  outputs.commit();
  std::cout << fmt::format("wrote {}: {}x{} pixels, {} covered\n", args.out, scene.grid.width, scene.grid.height,
                           scene.geometry.coveredPixels());
  return 0;
}

}  // namespace

Subcommand addGBufferCommand(CLI::App& app) {
  auto* command =
      app.add_subcommand("gbuffer", "write what a scene's pixels see (normal, view, coverage, BRDF) as a G-buffer EXR");
  auto args = std::make_shared<GBufferArgs>();
  args->scene.add(*command);
  command->add_option("--out", args->out, "the G-buffer: N, view, A, rho_d, rho_s, phong_n")->capture_default_str();
  return {command, [args] { return runGBuffer(*args); }};
}

}  // namespace misalloc
