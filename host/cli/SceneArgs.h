#pragma once
#include <CLI/CLI.hpp>
#include <string>

#include "scene/Scene.h"

namespace misalloc {

// The scene options of render, reference and compare: envmap, BRDF grid, size, view,
// sampler, and render's envmap pdf.
struct SceneArgs {
  SceneOptions options;
  std::string size = "128x128", view, sampler = "alias", envmapPdf = "plain";
  CLI::Option* envmapPdfOption = nullptr;
  const CLI::App* app = nullptr;  // the command the options were added to
  bool plainPdfByDefault = false;

  void add(CLI::App& command);
  // [Kar19]: render only; compare takes a list. Its default is defaultEnvmapPdf's, or the
  // plain one for envmap sampling alone (usePlainPdfByDefault).
  void addEnvmapPdf(CLI::App& command);
  void usePlainPdfByDefault();

  // The options with --size, --view, --envmap-sampler and --envmap-pdf parsed; throws
  // InputError.
  SceneOptions parsed();
  // The scene, with a warning for each repair its envmap needed.
  Scene make();

 private:
  void writeBackResolved();
};

}  // namespace misalloc
