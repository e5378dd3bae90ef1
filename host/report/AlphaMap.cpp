#include "report/AlphaMap.h"

#include <algorithm>
#include <cmath>

#include "AtomicFile.h"
#include "KernelCode.h"
#include "scene/PngIO.h"

namespace misalloc {

std::string alphaPngPath(const std::string& exrPath) {
  const std::string ext = ".exr";
  bool hasExt = exrPath.size() >= ext.size() && exrPath.compare(exrPath.size() - ext.size(), ext.size(), ext) == 0;
  return (hasExt ? exrPath.substr(0, exrPath.size() - ext.size()) : exrPath) + ".png";
}

AlphaMapFiles encodeAlphaMaps(const Scene& scene, const Rendering& rendering) {
  const int W = scene.grid.width, H = scene.grid.height, M = scene.techniqueCount();
  std::vector<std::string> names;
  for (const auto& t : scene.techniqueNames()) names.push_back("alpha." + t);
  std::vector<std::vector<float>> planes(M, std::vector<float>(size_t(W) * H));
  std::vector<uint8_t> rgb(size_t(W) * H * 3, 0);
  for (size_t p = 0; p < size_t(W) * H; ++p) {
    for (int k = 0; k < M; ++k) planes[k][p] = float(rendering.alpha[p * M + k]);
    if (!rendering.image.covers(p)) continue;  // the background took no samples: black
    double share[3] = {0, 0, 0};               // red, green, blue
    for (int k = 0; k < M; ++k) {
      const int role = scene.options.techniqueRole(k);
      share[role == kern::ROLE_ENVMAP ? 2 : role == kern::ROLE_PRODUCT ? 1 : 0] += rendering.alpha[p * M + k];
    }
    for (int c = 0; c < 3; ++c) rgb[3 * p + c] = uint8_t(std::lround(255 * std::clamp(share[c], 0.0, 1.0)));
  }
  return {encodeExrChannels(W, H, names, planes), encodePng(W, H, rgb)};
}

void writeAlphaMaps(const std::string& path, const Scene& scene, const Rendering& rendering) {
  AlphaMapFiles files = encodeAlphaMaps(scene, rendering);
  writeFileAtomically(path, files.exr);
  writeFileAtomically(alphaPngPath(path), files.png);
}

}  // namespace misalloc
