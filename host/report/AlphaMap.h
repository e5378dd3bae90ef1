#pragma once
#include <string>

#include "render/Render.h"

namespace misalloc {

// The per-pixel allocation as two files: an EXR with one channel alpha.<technique>
// per technique, and a false-colour PNG as in [HS14] Fig. 5.5: blue = envmap sampling
// only, red = BRDF sampling only (both lobes when split), green = the product technique
// only (--product), black the background, which took no samples.
struct AlphaMapFiles {
  std::string exr, png;
};
AlphaMapFiles encodeAlphaMaps(const Scene& scene, const Rendering& rendering);

// Writes encodeAlphaMaps's files: the EXR to `path`, the PNG to alphaPngPath(path).
void writeAlphaMaps(const std::string& path, const Scene& scene, const Rendering& rendering);

std::string alphaPngPath(const std::string& exrPath);

}  // namespace misalloc
