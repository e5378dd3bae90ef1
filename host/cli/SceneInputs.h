#pragma once
#include <vector>

#include "OutputSet.h"
#include "scene/Scene.h"

namespace misalloc {

// The files that the scenes read (envmap, G-buffer, mesh): no output may replace one.
std::vector<NamedFile> sceneInputs(const std::vector<SceneOptions>& scenes);

}  // namespace misalloc
