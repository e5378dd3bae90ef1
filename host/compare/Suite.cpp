#include "compare/Suite.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace misalloc {

std::string caseLabel(const SceneOptions& scene) {
  std::string name = scene.envmap;
  if (name.size() > 4 && name.compare(name.size() - 4, 4, ".exr") == 0)
    name = std::filesystem::path(name).stem().string();
  if (scene.shape != "plane") name += "-" + scene.shape;
  if (!scene.gbuffer.path.empty()) name += "-" + std::filesystem::path(scene.gbuffer.path).stem().string();
  if (!scene.mesh.path.empty()) name += "-" + std::filesystem::path(scene.mesh.path).stem().string();
  for (char& ch : name)
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '.' && ch != '_' && ch != '-') ch = '_';
  if (scene.sampler == EnvmapSampler::Cdf) name += "-cdf";
  if (scene.splitBrdf) name += "-split";
  if (scene.product) name += "-product";
  if (scene.envmapPdf.compensated()) name += "-comp" + envmapPdfName(scene.envmapPdf).substr(sizeof("compensated"));
  if (scene.envmapPdf.optimal()) name += "-optimal";
  if (scene.envmapPdf.pixelOptimal()) {
    // "optimal-pixel", "optimal-pixel:N" or "optimal-pixel:N/P" as "-optimal-pixel", "-N", "-N-P".
    std::string spec = envmapPdfName(scene.envmapPdf);
    std::replace(spec.begin(), spec.end(), ':', '-');
    std::replace(spec.begin(), spec.end(), '/', '-');
    name += "-" + spec;
  }
  return name;
}

std::vector<CompareCase> suiteCases(int width, int height) {
  std::vector<CompareCase> cases;
  SceneOptions base;
  base.width = width;
  base.height = height;
  for (const std::string& map : shippedEnvmapNames()) {
    SceneOptions o = base;
    o.envmap = map;
    cases.push_back({caseLabel(o), o, {}, {}});
  }
  SceneOptions cdf = base;
  cdf.sampler = EnvmapSampler::Cdf;
  cases.push_back({caseLabel(cdf), cdf, {}, {}});
  return cases;
}

}  // namespace misalloc
