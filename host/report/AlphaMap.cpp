#include "report/AlphaMap.h"

#include <cmath>

#include "AtomicFile.h"
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
    double envmap = rendering.alpha[p * M];
    rgb[3 * p + 0] = uint8_t(std::lround(255 * (1 - envmap)));
    rgb[3 * p + 2] = uint8_t(std::lround(255 * envmap));
  }
  return {encodeExrChannels(W, H, names, planes), encodePng(W, H, rgb)};
}

void writeAlphaMaps(const std::string& path, const Scene& scene, const Rendering& rendering) {
  AlphaMapFiles files = encodeAlphaMaps(scene, rendering);
  writeFileAtomically(path, files.exr);
  writeFileAtomically(alphaPngPath(path), files.png);
}

}  // namespace misalloc
