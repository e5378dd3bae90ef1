#pragma once
#include <string>

#include "render/Render.h"

namespace misalloc {

// Writes the per-pixel allocation: `path` (EXR) holds one channel alpha.<technique> per
// technique; `path` with .png for .exr a false-colour picture as in [HS14] Fig. 5.5:
// blue = envmap sampling only, red = BRDF sampling only (both lobes when split).
void writeAlphaMaps(const std::string& path, const Scene& scene, const Rendering& rendering);

std::string alphaPngPath(const std::string& exrPath);

}  // namespace misalloc
