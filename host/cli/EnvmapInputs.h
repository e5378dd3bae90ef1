#pragma once
#include <vector>

#include "OutputSet.h"
#include "scene/Scene.h"

namespace misalloc {

// The envmap files that the scenes read: no output may replace one.
std::vector<NamedFile> envmapInputs(const std::vector<SceneOptions>& scenes);

}  // namespace misalloc
