#include "render/Reference.h"

#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "AtomicFile.h"

#include "Error.h"
#include "render/Method.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// FNV-1a, 64 bits: a stable content hash for cache keys.
struct Fnv1a {
  uint64_t h = 0xcbf29ce484222325ull;
  void add(const void* data, size_t n) {
    auto* p = static_cast<const unsigned char*>(data);
    for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  }
  void add(const std::string& s) { add(s.data(), s.size() + 1); }
  template <typename T>
  void addValue(T v) {
    add(&v, sizeof v);
  }
};

}  // namespace

std::optional<RgbImage> analyticReference(const Scene& scene) {
  const float K = scene.envmap.coskExponent;
  if (K < 0 || scene.options.viewTheta != 0) return std::nullopt;
  RgbImage image;
  image.width = scene.grid.width;
  image.height = scene.grid.height;
  image.rgb.reserve(scene.grid.pixels.size() * 3);
  for (const auto& p : scene.grid.pixels) {
    double L = 2.0 * p.rhoD / (K + 2.0) + double(p.rhoS) * (p.n + 2.0) / (p.n + K + 2.0);  // [HS14] eq. 6.17
    for (int c = 0; c < 3; ++c) image.rgb.push_back(float(L));
  }
  return image;
}

RgbImage sampleReference(StageSampler& sampler, const Scene& scene, int spp, uint64_t seed,
                         const std::function<void(int done, int spp)>& progress) {
  constexpr int maxStage = 4096;
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  std::vector<double> sum(size_t(pixels) * 3, 0.0);
  StagePlan plan = singleStagePlan(scene, Method::Equal, std::min(spp, maxStage));
  for (int done = 0; done < spp;) {
    int n = std::min(maxStage, spp - done);
    if (n != plan.stageSamples) plan = singleStagePlan(scene, Method::Equal, n);
    for (int p = 0; p < pixels; ++p)
      for (int k = 0; k < M; ++k) plan.firstIndex[size_t(p) * M + k] = uint32_t(done / M + (k < done % M ? 1 : 0));
    StageResult stage = sampler.run(plan, seed);
    // Each stage is an unbiased estimate; weighting by its share of the samples keeps
    // the average unbiased and gives every sample the same weight.
    for (size_t i = 0; i < sum.size(); ++i) sum[i] += stage.rgb[i] * n / spp;
    done += n;
    if (progress) progress(done, spp);
  }
  RgbImage image;
  image.width = scene.grid.width;
  image.height = scene.grid.height;
  image.rgb.assign(sum.begin(), sum.end());
  return image;
}

std::string referenceKey(const Scene& scene, int spp) {
  Fnv1a h;
  const EnvmapTables& env = scene.tables;
  h.addValue(env.width);
  h.addValue(env.height);
  // The texels' RGB in order, without their probabilities: the same bytes as the
  // envmap's image, so keys outlive the change from hashing the image.
  for (size_t t = 0; t < env.texels.size(); t += 4) h.add(&env.texels[t], 3 * sizeof(float));
  h.addValue(scene.envmap.coskExponent);
  h.add(scene.grid.spec);
  h.addValue(scene.grid.width);
  h.addValue(scene.grid.height);
  h.addValue(scene.options.viewTheta);
  h.addValue(scene.options.viewPhi);
  h.addValue(spp);
  return fmt::format("{:016x}", h.h);
}

std::string defaultCacheDir() {
  if (const char* dir = std::getenv("MISALLOC_CACHE_DIR")) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME")) return fmt::format("{}/misalloc", xdg);
  if (const char* home = std::getenv("HOME")) return fmt::format("{}/.cache/misalloc", home);
  return ".cache/misalloc";
}

std::optional<std::string> referenceCachePath(const Scene& scene, int spp, const std::string& cacheDir) {
  if (analyticReference(scene)) return std::nullopt;
  return (fs::path(cacheDir) / "references" / (referenceKey(scene, spp) + ".exr")).string();
}

namespace {

constexpr const char* kReferenceEstimator = "equal-count MIS, plain envmap pdf";

uint64_t pixelChecksum(const RgbImage& image) {
  Fnv1a h;
  h.add(image.rgb.data(), image.rgb.size() * sizeof(float));
  return h.h;
}

// What a cache entry says it is; the checksum is of its pixels as read.
ExrAttributes cacheClaims(const Scene& scene, int spp, const RgbImage& image) {
  return {{"misalloc.reference.key", referenceKey(scene, spp)},
          {"misalloc.reference.estimator", kReferenceEstimator},
          {"misalloc.reference.spp", std::to_string(spp)},
          {"misalloc.reference.size", fmt::format("{}x{}", scene.grid.width, scene.grid.height)},
          {"misalloc.reference.checksum", fmt::format("{:016x}", pixelChecksum(image))}};
}

// The cached image, or why it cannot be trusted.
struct CacheEntry {
  std::optional<RgbImage> image;
  std::string problem;
};

CacheEntry readCacheEntry(const std::string& path, const Scene& scene, int spp) {
  ExrAttributes found;
  RgbImage image;
  try {
    image = readExr(path, nullptr, &found);
  } catch (const InputError& e) {
    return {std::nullopt, e.what()};
  }
  for (const auto& [name, expected] : cacheClaims(scene, spp, image)) {
    auto it = found.find(name);
    if (it == found.end()) return {std::nullopt, fmt::format("it has no {}", name)};
    if (it->second != expected)
      return {std::nullopt, fmt::format("its {} is {}, not {}", name, it->second, expected)};
  }
  return {std::move(image), ""};
}

void reportProgress(int done, int spp) {
  std::cerr << fmt::format("misalloc: reference {}/{} spp\n", done, spp) << std::flush;
}

}  // namespace

Reference findReference(const Scene& scene, int spp, const std::string& cacheDir,
                        const std::function<StageSampler&()>& sampler) {
  if (auto analytic = analyticReference(scene)) return Reference{*analytic, "analytic ([HS14] eq. 6.17)", ""};
  const std::string path = *referenceCachePath(scene, spp, cacheDir);
  const std::string source = fmt::format("{}, {} spp", kReferenceEstimator, spp);
  std::string recomputed;
  std::error_code ec;
  if (fs::exists(path, ec)) {
    CacheEntry entry = readCacheEntry(path, scene, spp);
    if (entry.image) return Reference{std::move(*entry.image), source + " (cached)", path};
    std::cerr << fmt::format("misalloc: warning: the cached reference {} is not trusted: {}; computing it again\n",
                             path, entry.problem);
    recomputed = fmt::format(" (computed again: the cached entry was not trusted: {})", entry.problem);
  }
  fs::create_directories(fs::path(path).parent_path(), ec);
  if (ec)
    throw InputError(fmt::format("--cache-dir {}: cannot create {}: {}", cacheDir, fs::path(path).parent_path().string(),
                                 ec.message()));
  std::cerr << fmt::format("misalloc: computing the reference ({}, {} spp, {}x{} pixels) once; it is cached in {}\n",
                           kReferenceEstimator, spp, scene.grid.width, scene.grid.height,
                           fs::path(path).parent_path().string());
  // A seed of its own (top bit set), so a render with a small seed is independent of it.
  RgbImage image = sampleReference(sampler(), scene, spp, 0x8000000000005eedull, reportProgress);
  writeFileAtomically(path, encodeExr(image, cacheClaims(scene, spp, image)));
  return Reference{image, source + recomputed, path};
}

}  // namespace misalloc
