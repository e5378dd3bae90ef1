#include "cli/EnvmapInputs.h"

#include <filesystem>

namespace misalloc {

std::vector<NamedFile> envmapInputs(const std::vector<SceneOptions>& scenes) {
  std::vector<NamedFile> inputs;
  for (const SceneOptions& o : scenes) {
    std::string file = resolveEnvmapSpec(o.envmap);
    if (std::filesystem::exists(file)) inputs.push_back({"--envmap", file});
  }
  return inputs;
}

}  // namespace misalloc
