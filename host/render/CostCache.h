#pragma once
// Calibrated cost models (sampling/CostModel.h) kept on disk beside the references and
// the optimal pdf's tables, so that a render's allocations, and so its image, repeat
// on its machine: a calibration times this run's own launches, and no two agree. An
// entry is keyed by what the launch times depend on: the devices and the kernels as
// built (StageSampler::launchIdentity), the sampler's config, the envmap pdf's tables
// and the whole image's scene. A band's sampler renders part of the image and takes the
// image's entry, so that every band allocates with the same costs. An entry holds a
// checksum of its contents; one that does not read back whole is calibrated again and
// replaced, never used.
#include <string>

#include "sampling/StageSampler.h"

namespace misalloc {

struct CostCacheRequest {
  std::string cacheDir;  // empty: calibrated, not cached
  bool measure = false;  // --cost measure: calibrated again, the entry replaced
};

// `image`: the scene whose pixels `sampler` renders, or all of whose rows a band's are.
std::string costCacheKey(const StageSampler& sampler, const Scene& image);

// <cacheDir>/costs/<key>.json
std::string costCachePath(const std::string& cacheDir, const std::string& key);

// Sets `sampler`'s cost model: the cached entry where there is a sound one and the
// request does not measure, else a calibration on `sampler`, then written to the cache.
// Runs that share a cache take one calibration per key (a lock beside the entry). A
// cache that cannot be written is named on stderr, and the render allocates with its
// own calibration.
void provideCostModel(StageSampler& sampler, const Scene& image, const CostCacheRequest& request);

}  // namespace misalloc
