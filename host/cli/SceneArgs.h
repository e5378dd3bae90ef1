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

  void add(CLI::App& command);
  // [Kar19]: render only; a reference is equal MIS with the plain pdf, compare takes a list.
  void addEnvmapPdf(CLI::App& command);

  // The options with --size, --view, --envmap-sampler and --envmap-pdf parsed; throws
  // InputError.
  SceneOptions parsed();
  // The scene, with a warning for each repair its envmap needed.
  Scene make();
};

}  // namespace misalloc
