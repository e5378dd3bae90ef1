#include "render/Reference.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "AtomicFile.h"
#include "ContentHash.h"
#include "Error.h"
#include "FileLock.h"
#include "Interruption.h"
#include "render/Method.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

constexpr uint32_t kReferenceFirstIndex = 1u << 31;
constexpr uint64_t kReferenceSeed = 0x8000000000005eedull;

}  // namespace

std::optional<RgbImage> analyticReference(const Scene& scene) {
  const float K = scene.envmap.coskExponent;
  // Eq. 6.17 holds for a view along the normal, and the cos^K map about it.
  if (K < 0 || !scene.geometry.flat() || scene.geometry.pixels.front().mirror != Vec3f{0.0f, 0.0f, 1.0f})
    return std::nullopt;
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

Scene referenceScene(const Scene& scene) {
  SceneOptions options = scene.options;
  // The same reference with or without the product technique, which changes the noise only.
  options.product = false;
  options.envmapPdf = defaultEnvmapPdf(options);
  return makeScene(options);
}

std::string referenceEstimator(const SceneOptions& scene) {
  return fmt::format("equal-count MIS, {} envmap pdf", envmapPdfName(defaultEnvmapPdf(scene)));
}

SampledReference sampleReference(StageSampler& sampler, const Scene& scene, int spp, uint64_t seed,
                                 const std::function<void(int done, int spp)>& progress) {
  constexpr int kMaxBatch = 4096, kBatches = 16;
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  if (spp < 2 * M)
    throw InputError(
        fmt::format("--reference-spp {}: a sampled reference needs two batches of {} samples, one per "
                    "technique each, to estimate its own variance",
                    spp, M));
  const int batches = std::max(std::min(kBatches, spp / M), (spp + kMaxBatch - 1) / kMaxBatch);
  // Per pixel and channel: Σ_b n_b x_b and Σ_b n_b x_b² over the batches' estimates x_b.
  std::vector<double> sum(size_t(pixels) * 3, 0.0), sumSquares(sum.size(), 0.0);
  // Sample indices from 2³¹ on: a render's never reach them (its spp is an int), so
  // the reference's random numbers are its own whatever the render's seed.
  std::vector<uint32_t> taken(size_t(pixels) * M, kReferenceFirstIndex);
  for (int b = 0, done = 0; b < batches; ++b) {
    const int n = spp / batches + (b < spp % batches ? 1 : 0);
    StagePlan plan = singleStagePlan(scene, Method::Equal, n);
    plan.firstIndex = taken;  // each batch takes samples of its own: independent estimates
    for (size_t i = 0; i < taken.size(); ++i) taken[i] += uint32_t(plan.counts[i]);
    checkInterruption();
    StageResult batch = sampler.run(plan, seed);
    for (size_t i = 0; i < sum.size(); ++i) {
      sum[i] += double(n) * batch.rgb[i];
      sumSquares[i] += double(n) * batch.rgb[i] * batch.rgb[i];
    }
    done += n;
    if (progress) progress(done, spp);
  }
  // The batches are independent unbiased estimates; weighting each by its share of the
  // samples gives every sample the same weight. With σ² a sample's variance,
  // Σ_b n_b (x_b − x̄)² / (B − 1) estimates σ², and the mean's variance is σ²/N.
  SampledReference out{
      RgbImage{scene.grid.width, scene.grid.height, std::vector<float>(sum.size()), scene.geometry.alpha()},
      std::vector<float>(sum.size())};
  for (size_t i = 0; i < sum.size(); ++i) {
    const double mean = sum[i] / spp;
    out.image.rgb[i] = float(mean);
    out.standardError[i] =
        float(std::sqrt(std::max(0.0, sumSquares[i] - spp * mean * mean) / ((batches - 1) * double(spp))));
  }
  return out;
}

std::string referenceKey(const Scene& scene, int spp) {
  ContentHash h;
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
  // Per-pixel frames, BRDFs and coverage: every one of them (a flat scene's are the view
  // and the grid above).
  if (!scene.geometry.flat() || scene.geometry.hasBackground()) {
    const SceneGeometry& g = scene.geometry;
    h.addVector(g.pixels);
    h.addVector(g.covered);
    h.addVector(scene.grid.pixels);
  }
  h.addValue(spp);
  h.add(referenceEstimator(scene.options));
  return fmt::format("{:016x}", h.h);
}

std::string defaultCacheDir() {
  if (const char* dir = std::getenv("MISALLOC_CACHE_DIR")) return dir;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME")) return fmt::format("{}/misalloc", xdg);
  if (const char* home = std::getenv("HOME")) return fmt::format("{}/.cache/misalloc", home);
  return ".cache/misalloc";
}

namespace {

std::string cacheEntryPath(const std::string& key, const std::string& cacheDir) {
  return (fs::path(cacheDir) / "references" / (key + ".exr")).string();
}

// Beside the entries, not among them: a folder of entries holds entries only.
std::string cacheLockPath(const std::string& key, const std::string& cacheDir) {
  return (fs::path(cacheDir) / "locks" / (key + ".lock")).string();
}

// The cache entry's channels: the image, then the standard deviation of its error.
const std::vector<std::string> kErrorChannels{"standard_error.R", "standard_error.G", "standard_error.B"};

uint64_t pixelChecksum(const SampledReference& reference) {
  ContentHash h;
  h.addVector(reference.image.rgb);
  h.addVector(reference.standardError);
  return h.h;
}

// What a cache entry says it is; the checksum is of its pixels as read.
ExrAttributes cacheClaims(const std::string& key, const Scene& scene, int spp, const SampledReference& reference) {
  return {{"misalloc.reference.key", key},
          {"misalloc.reference.estimator", referenceEstimator(scene.options)},
          {"misalloc.reference.spp", std::to_string(spp)},
          {"misalloc.reference.size", fmt::format("{}x{}", scene.grid.width, scene.grid.height)},
          {"misalloc.reference.checksum", fmt::format("{:016x}", pixelChecksum(reference))}};
}

std::string encodeCacheEntry(const std::string& key, const Scene& scene, int spp, const SampledReference& reference) {
  std::vector<std::vector<float>> planes(6, std::vector<float>(reference.standardError.size() / 3));
  for (size_t p = 0; p < planes[0].size(); ++p)
    for (int c = 0; c < 3; ++c) {
      planes[c][p] = reference.image.rgb[3 * p + c];
      planes[3 + c][p] = reference.standardError[3 * p + c];
    }
  std::vector<std::string> names{"R", "G", "B"};
  names.insert(names.end(), kErrorChannels.begin(), kErrorChannels.end());
  return encodeExrChannels(reference.image.width, reference.image.height, names, planes,
                           cacheClaims(key, scene, spp, reference));
}

// The cached reference, or why it cannot be trusted.
struct CacheEntry {
  std::optional<SampledReference> reference;
  std::string problem;
};

CacheEntry readCacheEntry(const std::string& path, const std::string& key, const Scene& scene, int spp) {
  ExrAttributes found;
  SampledReference entry;
  try {
    entry.image = readExr(path, nullptr, &found);
    std::vector<std::vector<float>> errors = readExrChannels(path, kErrorChannels);
    entry.standardError.resize(entry.image.rgb.size());
    if (errors[0].size() * 3 != entry.standardError.size())
      return {std::nullopt, "its standard error is of another size"};
    for (size_t p = 0; p < errors[0].size(); ++p)
      for (int c = 0; c < 3; ++c) entry.standardError[3 * p + c] = errors[c][p];
  } catch (const InputError& e) {
    return {std::nullopt, e.what()};
  }
  for (const auto& [name, expected] : cacheClaims(key, scene, spp, entry)) {
    auto it = found.find(name);
    if (it == found.end()) return {std::nullopt, fmt::format("it has no {}", name)};
    if (it->second != expected) return {std::nullopt, fmt::format("its {} is {}, not {}", name, it->second, expected)};
  }
  return {std::move(entry), ""};
}

void reportProgress(int done, int spp) {
  std::cerr << fmt::format("misalloc: reference {}/{} spp\n", done, spp) << std::flush;
}

}  // namespace

std::optional<std::string> referenceCachePath(const Scene& scene, int spp, const std::string& cacheDir) {
  if (analyticReference(scene)) return std::nullopt;
  return cacheEntryPath(referenceKey(scene, spp), cacheDir);
}

namespace {

// The cache entry at `path` if it can be trusted; else why not, in `problem` (empty
// when there is no entry).
std::optional<Reference> trustedEntry(const std::string& path, const std::string& key, const Scene& scene, int spp,
                                      const std::string& source, std::string& problem) {
  std::error_code ec;
  if (!fs::exists(path, ec)) return std::nullopt;
  CacheEntry entry = readCacheEntry(path, key, scene, spp);
  if (entry.reference)
    return Reference{std::move(entry.reference->image), std::move(entry.reference->standardError), source + " (cached)",
                     path};
  problem = entry.problem;
  return std::nullopt;
}

}  // namespace

Reference findReference(const Scene& scene, int spp, const std::string& cacheDir, const SamplerFactory& makeSampler) {
  if (auto analytic = analyticReference(scene)) return Reference{*analytic, {}, "analytic ([HS14] eq. 6.17)", ""};
  // The key hashes every texel: computed once for the path and the claims.
  const std::string key = referenceKey(scene, spp), path = cacheEntryPath(key, cacheDir);
  const std::string source = fmt::format("{}, {} spp", referenceEstimator(scene.options), spp);
  std::string problem;
  if (auto cached = trustedEntry(path, key, scene, spp, source, problem)) return std::move(*cached);
  const std::string lockPath = cacheLockPath(key, cacheDir);
  for (const fs::path& folder : {fs::path(path).parent_path(), fs::path(lockPath).parent_path()}) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec)
      throw InputError(fmt::format("--cache-dir {}: cannot create {}: {}", cacheDir, folder.string(), ec.message()));
  }
  // Shards of one scene may share the cache (a shared file system): one computes the
  // entry under the lock, the others wait and read it, so no reference is computed
  // twice at once; the entry itself is written beside and renamed into place, so no
  // reader ever sees half of one.
  FileLock lock(lockPath, [&] {
    std::cerr << fmt::format("misalloc: another process is computing the reference {}; waiting for it\n", path)
              << std::flush;
  });
  if (auto cached = trustedEntry(path, key, scene, spp, source, problem)) return std::move(*cached);
  std::string recomputed;
  if (!problem.empty()) {
    std::cerr << fmt::format("misalloc: warning: the cached reference {} is not trusted: {}; computing it again\n",
                             path, problem);
    recomputed = fmt::format(" (computed again: the cached entry was not trusted: {})", problem);
  }
  std::cerr << fmt::format("misalloc: computing the reference ({}, {} spp, {}x{} pixels) once; it is cached in {}\n",
                           referenceEstimator(scene.options), spp, scene.grid.width, scene.grid.height,
                           fs::path(path).parent_path().string());
  const Scene sampledScene = referenceScene(scene);
  std::unique_ptr<StageSampler> sampler = makeSampler(sampledScene);
  SampledReference sampled = sampleReference(*sampler, sampledScene, spp, kReferenceSeed, reportProgress);
  writeFileAtomically(path, encodeCacheEntry(key, scene, spp, sampled));
  return Reference{std::move(sampled.image), std::move(sampled.standardError), source + recomputed, path};
}

}  // namespace misalloc
