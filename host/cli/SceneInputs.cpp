#include "cli/SceneInputs.h"

#include <filesystem>

namespace misalloc {

std::vector<NamedFile> sceneInputs(const std::vector<SceneOptions>& scenes) {
  std::vector<NamedFile> inputs;
  for (const SceneOptions& o : scenes) {
    if (!o.envmapTexels) {
      std::string file = resolveEnvmapSpec(o.envmap);
      if (std::filesystem::exists(file)) inputs.push_back({"--envmap", file});
    }
    if (!o.gbuffer.path.empty() && !o.gbuffer.channels) inputs.push_back({"--gbuffer", o.gbuffer.path});
    if (!o.mesh.path.empty()) inputs.push_back({"--mesh", o.mesh.path});
  }
  return inputs;
}

}  // namespace misalloc
