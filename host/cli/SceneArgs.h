#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "scene/Scene.h"

namespace misalloc {

// The scene options of render, reference and compare: envmap, BRDF grid, size, view,
// sampler, and render's envmap pdf.
struct SceneArgs {
  SceneOptions options;
  std::string size = "128x128", view = "0", sampler = "alias", envmapPdf = "plain";
  CLI::Option* envmapPdfOption = nullptr;

  void add(CLI::App& command);
  // [Kar19]: render only; compare takes a list. Its default is the optimal pdf, the
  // largest gain misalloc has, or the plain one where the optimal one cannot serve:
  // with --split-brdf (not implemented) and for envmap sampling alone (usePlainPdfByDefault).
  void addEnvmapPdf(CLI::App& command);
  void usePlainPdfByDefault();

  // The options with --size, --view, --envmap-sampler and --envmap-pdf parsed; throws
  // InputError.
  SceneOptions parsed();
  // The scene, with a warning for each repair its envmap needed.
  Scene make();
};

}  // namespace misalloc
