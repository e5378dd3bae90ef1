#pragma once
// The optimal pdf's tables ([Kar19] eqs. 5–10, buildOptimalEnvmapTables) kept on disk
// beside the references, so that a scene's second render does not build them again.
// An entry is keyed by everything the tables are built from: the map's texels, the
// sampler, every pixel's BRDF, the view, the bank's options and the file format. It
// holds a checksum of its contents; an entry that does not read back whole (another
// format, another key, a size or checksum that does not match) is rebuilt and
// replaced, never used.
#include <array>
#include <optional>
#include <string>

#include "distributions/EnvmapDistribution.h"
#include "distributions/OptimalBank.h"
#include "scene/BrdfGrid.h"
#include "scene/Envmap.h"

namespace misalloc {

std::string bankCacheKey(const Envmap& envmap, EnvmapSampler sampler, const BrdfGrid& grid,
                         const std::array<float, 3>& mirror, const OptimalBankOptions& options = {});

// <cacheDir>/banks/<key>.bin
std::string bankCachePath(const std::string& cacheDir, const std::string& key);

// The tables of the entry for `key` (bankFromCache set), their texels' RGB from
// `image`; none where there is no entry, or a damaged one, which is named on stderr.
std::optional<EnvmapTables> readCachedBank(const std::string& cacheDir, const std::string& key,
                                           const RgbImage& image);

// Writes the entry for `key`, all or nothing. A cache that cannot be written is named on
// stderr and left as it is: the tables are built again next time.
void writeCachedBank(const std::string& cacheDir, const std::string& key, const EnvmapTables& tables);

}  // namespace misalloc
