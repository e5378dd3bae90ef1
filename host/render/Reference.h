#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>
#include <string>

#include "sampling/Sampler.h"
#include "scene/ExrIO.h"

namespace misalloc {

struct Reference {
  RgbImage image;
  // Per pixel and channel, as image.rgb: the estimated standard deviation of the
  // sampled image's own error, √Var(r) (a variance could overflow a float where a
  // radiance does not); empty for an exact (analytic) reference and for a file given
  // by the user, whose error is not known and taken as 0.
  std::vector<float> standardError;
  std::string source;  // "analytic ([HS14] eq. 6.17)", or how it was sampled
  std::string path;    // the cached file, if any
};

// A sampled reference and the standard deviation of its error, as Reference's.
struct SampledReference {
  RgbImage image;
  std::vector<float> standardError;
};

// [HS14] eq. 6.17: for R = cos^K θ and ω_o along the normal, L = R(2ρd/(K+2) +
// ρs(n+2)/(n+K+2)), exact. Empty for any other scene.
std::optional<RgbImage> analyticReference(const Scene& scene);

// The scene whose estimator a sampled reference of `scene` runs: equal counts with the
// optimal envmap pdf ([Kar19] eq. 9, the table for C = 1/2), the best unbiased
// estimator misalloc has, or with the plain pdf where the optimal one is not
// implemented (the BRDF split into lobes). Reads the envmap again: built only when a
// reference is computed.
Scene referenceScene(const Scene& scene);

// What referenceScene's estimator is, in words, for the cache entry and the reports.
std::string referenceEstimator(const SceneOptions& scene);

// A converged image: equal-count MIS with `spp` samples per pixel, in independent
// batches of at most 4096 samples (no kernel launch runs for long) and at least M, at
// most 16 of them where the budget allows: the spread of the batches' estimates gives
// the variance of the image's own error. Throws InputError for a budget of fewer than
// two batches of M samples. `progress`, if given, hears the samples done after each batch.
SampledReference sampleReference(StageSampler& sampler, const Scene& scene, int spp, uint64_t seed,
                                 const std::function<void(int done, int spp)>& progress = {});

// The cache key of a scene's reference: everything the pixel values depend on (the
// envmap's texels, the analytic exponent, the grid, size and view), the spp and the
// estimator (referenceEstimator), not the pdf the render asked for or the sampler.
std::string referenceKey(const Scene& scene, int spp);

// $MISALLOC_CACHE_DIR, else $XDG_CACHE_HOME/misalloc, else ~/.cache/misalloc.
std::string defaultCacheDir();

// The file that caches the scene's sampled reference, read and written by
// findReference; none for a scene with an analytic one. An input of the run: no
// output may be written over it.
std::optional<std::string> referenceCachePath(const Scene& scene, int spp, const std::string& cacheDir);

// The analytic reference if there is one, else the cached one, else a sampled one of
// referenceScene(scene), which is then cached; `makeSampler` (a sampler without
// statistics for the scene it is given) is called only then. A cache
// entry carries in its header what it claims to be (the scene's key, the estimator,
// spp, size) and a checksum of its pixels; one that cannot be read, or whose claims or
// checksum do not match, is never trusted: it is reported on stderr and in the source,
// and computed again. Progress of a computation goes to stderr. Processes that share the
// cache (shards on a shared file system) compute an entry one at a time, under a lock
// (CACHE_DIR/locks/KEY.lock beside CACHE_DIR/references/KEY.exr, FileLock.h): the others
// wait and then read the entry.
using SamplerFactory = std::function<std::unique_ptr<StageSampler>(const Scene&)>;
Reference findReference(const Scene& scene, int spp, const std::string& cacheDir, const SamplerFactory& makeSampler);

}  // namespace misalloc
