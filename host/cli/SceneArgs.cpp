#include "cli/SceneArgs.h"

#include <fmt/format.h>

#include <iostream>
#include <vector>

#include "Error.h"
#include "MemoryBudget.h"
#include "NumberList.h"
#include "OptionRange.h"
#include "scene/SceneShape.h"

namespace misalloc {

void SceneArgs::add(CLI::App& command) {
  app = &command;
  const size_t firstSceneOption = command.get_options().size();
  command
      .add_option("--envmap", options.envmap,
                  "EXR path, shipped map name (forest_slope, rooitou_park, ...), constant[:R], cosk:K or "
                  "sun[:THETA,PHI,RADIUS,RATIO]")
      ->capture_default_str();
  command.add_option("--grid", options.grid, "seed000, general:RD0,RD1,N0,N1 or uniform:RD,RS,N")
      ->capture_default_str();
  command
      .add_option("--scene", options.shape,
                  "plane ([HS14]'s: the grid over the image), sphere (the grid over one sphere) or "
                  "spheres[:COLUMNSxROWS] (one BRDF of the grid per sphere, 4x4 by default)")
      ->capture_default_str();
  command.add_option("--gbuffer", options.gbuffer.path,
                     "an EXR G-buffer (shading normals, positions, alpha) instead of --scene; its size is the image's");
  command
      .add_option("--convention", options.gbuffer.convention,
                  "whose G-buffer and lat-long map: misalloc, mitsuba, blender or pbrt (their world frames and map "
                  "orientations)")
      ->capture_default_str();
  command.add_option("--normal-channels", options.gbuffer.normalChannels,
                     "the G-buffer's normal channels' prefix (PREFIX.X/Y/Z), if not the convention's");
  command.add_option("--position-channels", options.gbuffer.positionChannels,
                     "the G-buffer's position channels' prefix (PREFIX.X/Y/Z), if not the convention's");
  command.add_option("--camera-origin", options.gbuffer.cameraOrigin,
                     "X,Y,Z: the camera's position in the G-buffer's world (pbrt: from its header)");
  command.add_option("--view-direction", options.gbuffer.viewDirection,
                     "X,Y,Z: an orthographic G-buffer's view, towards the camera, in the G-buffer's space (in "
                     "place of positions and --camera-origin)");
  command.add_option("--mesh", options.mesh.path,
                     "a triangle mesh (OBJ, PLY, ...) or a shipped mesh's name (blob) instead of --scene, seen by "
                     "a pinhole camera from --camera-origin, in --convention's world");
  command.add_option("--camera-target", options.mesh.target, "X,Y,Z: where the mesh's camera looks")
      ->capture_default_str();
  command.add_option("--fov", options.mesh.verticalFovDegrees, "the mesh's camera's vertical field of view, degrees")
      ->capture_default_str();
  command.add_option("--gbuffer-space", options.gbuffer.space,
                     "camera or world: pbrt-v4's G-buffer space (default camera, pbrt's own default)");
  command.add_option("--size", size, "WxH pixels")->capture_default_str();
  command.add_option("--view", view,
                     "direction towards the camera: polar angle THETA[,PHI] in degrees (default 0 for the plane, "
                     "75 for spheres)");
  command.add_flag("--split-brdf", options.splitBrdf,
                   "the BRDF's diffuse and specular lobes as separate techniques (M=3)");
  command.add_flag("--product", options.product,
                   "envmap × BRDF × cos, tabulated per block of texels, as a third technique (M=3; [CL18])");
  command.add_option("--envmap-sampler", sampler, "alias (O(1)) or cdf (two binary searches)")->capture_default_str();
  command.add_option("--procedural-width", options.proceduralWidth, "texel width of procedural envmaps")
      ->capture_default_str()
      ->check(integerIn(2, 16384));
  const auto options = command.get_options();
  for (size_t i = firstSceneOption; i < options.size(); ++i) options[i]->group("Scene");
}

void SceneArgs::addEnvmapPdf(CLI::App& command) {
  envmapPdfOption = command.add_option(
      "--envmap-pdf", envmapPdf,
      "plain (∝ luminance), compensated[:C] (∝ max(0, L - 2(1-C) mean L), [Kar19] eq. 14; C default 0.5) or "
      "optimal ([Kar19] eq. 9 per BRDF bin and envmap share, a bank of tables) or optimal-pixel[:N[/P]] ([Kar19] "
      "eq. 6 for each pixel's own normal, view, BRDF and share over N x N/2 cells of the map, N a power of two from "
      "4 to 64, default 32, built as it renders; the stages that keep statistics, the pilot's, over P x P/2, P a "
      "power of two from 4 to N, default min(N, 16)); default optimal, plain with "
      "--split-brdf or --method envmap, optimal-pixel on spheres, G-buffers and meshes");
}

void SceneArgs::usePlainPdfByDefault() { plainPdfByDefault = true; }

SceneOptions SceneArgs::parsed() {
  std::tie(options.width, options.height) = parseImageSize(size);
  options.mesh.path = resolveMeshSpec(options.mesh.path);
  const double pixels = double(options.width) * options.height;
  requireHostMemory(fmt::format("--size {} ({:g} pixels × {} B)", size, pixels, kRenderBytesPerPixel),
                    pixels * kRenderBytesPerPixel);
  if (!options.gbuffer.path.empty())
    for (const char* option : {"--view", "--scene"})
      if (app && app->count(option) > 0)
        throw InputError(fmt::format("--gbuffer with {}: the G-buffer sets each pixel's view", option));
  if (!options.gbuffer.viewDirection.empty() && options.gbuffer.path.empty() && !options.gbuffer.channels)
    throw InputError(
        "--view-direction: the view of an orthographic G-buffer (--gbuffer); a built-in scene takes --view, a mesh "
        "its camera");
  if (!options.mesh.path.empty() && app && app->count("--view") > 0)
    throw InputError("--mesh with --view: the camera (--camera-origin, --camera-target) sets each pixel's view");
  const SceneShape shape = parseSceneShape(options.shape);
  if (view.empty()) view = fmt::format("{}", defaultViewTheta(shape));
  std::vector<double> angles = parseNumberList("--view", view, view, 0, "expected THETA[,PHI] in degrees");
  if (angles.size() > 2) throw InputError(fmt::format("--view {}: expected THETA[,PHI] in degrees", view));
  options.viewTheta = angles[0];
  options.viewPhi = angles.size() > 1 ? angles[1] : 0;
  options.sampler = parseEnvmapSampler(sampler);
  const bool defaultPdf = envmapPdfOption && envmapPdfOption->count() == 0;
  if (!defaultPdf)
    options.envmapPdf = parseEnvmapPdf(envmapPdf);
  else
    options.envmapPdf = plainPdfByDefault ? EnvmapPdf{} : defaultEnvmapPdf(options);
  writeBackResolved();
  return options;
}

// A run's identity (cli/RunIdentity.h) reads the options' variables: each holds what the
// run uses, in one spelling, also where its default depends on other options.
void SceneArgs::writeBackResolved() {
  size = fmt::format("{}x{}", options.width, options.height);
  view = fmt::format("{},{}", options.viewTheta, options.viewPhi);
  envmapPdf = envmapPdfName(options.envmapPdf);
}

Scene SceneArgs::make() {
  parsed();
  const int askedWidth = options.width, askedHeight = options.height;
  Scene scene = makeScene(options);
  if (!options.gbuffer.path.empty() && app && app->count("--size") > 0 &&
      (scene.grid.width != askedWidth || scene.grid.height != askedHeight))
    throw InputError(fmt::format("--size {}: the G-buffer {} is {}x{}", size, options.gbuffer.path, scene.grid.width,
                                 scene.grid.height));
  size = fmt::format("{}x{}", scene.grid.width, scene.grid.height);  // a G-buffer's, given or not
  if (isGBufferBrdf(scene.grid.spec) && app && app->count("--grid") > 0)
    throw InputError(fmt::format("--grid with --gbuffer {}: the G-buffer holds each pixel's BRDF (its channels {})",
                                 options.gbuffer.path, scene.grid.spec.substr(scene.grid.spec.find(':') + 1)));
  const ReadWarnings& repaired = scene.envmapWarnings;
  if (repaired.negativeValues > 0)
    std::cerr << fmt::format("misalloc: warning: {}: {} negative values set to 0 (first at {})\n", scene.envmapPath,
                             repaired.negativeValues, toString(repaired.firstNegative));
  if (scene.tables.uniformFallback)
    std::cerr << fmt::format("misalloc: warning: envmap '{}' is black: its sampling falls back to uniform\n",
                             options.envmap);
  if (scene.tables.requestedPdf.compensated() && !scene.tables.pdf.compensated())
    std::cerr << fmt::format(
        "misalloc: warning: envmap '{}': no texel exceeds 2(1-C) times the mean luminance; "
        "--envmap-pdf {} falls back to plain\n",
        options.envmap, envmapPdfName(scene.tables.requestedPdf));
  if ((scene.tables.requestedPdf.optimal() || scene.tables.requestedPdf.pixelOptimal()) &&
      !scene.tables.followsEnvmapShare())
    std::cerr << fmt::format("misalloc: warning: envmap '{}' is black: --envmap-pdf {} falls back to plain\n",
                             options.envmap, envmapPdfName(scene.tables.requestedPdf));
  return scene;
}

}  // namespace misalloc
