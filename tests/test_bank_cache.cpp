// The optimal pdf's tables cached on disk (distributions/BankCache.h): a hit gives the
// tables a build gives, bit for bit; a changed map, grid, view or sampler misses; a
// damaged entry is rebuilt, never used.
#include <sys/stat.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "SceneFixtures.h"
#include "distributions/BankCache.h"

using namespace misalloc;
using namespace misalloc::test;
namespace fs = std::filesystem;

namespace {

struct TempCache {
  fs::path path;
  TempCache() : path(fs::temp_directory_path() / fs::path("misalloc_bank_cache_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
  }
  ~TempCache() { fs::remove_all(path); }
};

void checkSameTables(const EnvmapTables& a, const EnvmapTables& b) {
  CHECK(a.width == b.width);
  CHECK(a.height == b.height);
  CHECK(a.texels == b.texels);
  CHECK(a.cdfTable == b.cdfTable);
  CHECK(a.aliasTable == b.aliasTable);
  CHECK(a.useCdf == b.useCdf);
  CHECK(a.cdfStepsRow == b.cdfStepsRow);
  CHECK(a.cdfStepsCol == b.cdfStepsCol);
  CHECK(a.pdf.kind == b.pdf.kind);
  CHECK(a.requestedPdf.kind == b.requestedPdf.kind);
  CHECK(a.meanLuminance == b.meanLuminance);
  CHECK(a.bankShares == b.bankShares);
  CHECK(a.blockLog2 == b.blockLog2);
  CHECK(a.brdfBins == b.brdfBins);
  CHECK(a.blockProbs == b.blockProbs);
  CHECK(a.brdfBinOfPixel == b.brdfBinOfPixel);
  CHECK(a.bankVariances.compensatedOverOptimalMax == b.bankVariances.compensatedOverOptimalMax);
  CHECK(a.bankVariances.entriesWithNegativeEq5 == b.bankVariances.entriesWithNegativeEq5);
}

// The scene with its tables looked up in `cacheDir`, and written there on a miss.
Scene optimalScene(const std::string& envmap, const std::string& grid, const std::string& cacheDir,
                   EnvmapSampler sampler = EnvmapSampler::Alias, double viewTheta = 0) {
  Scene s = smallScene(envmap, grid, 16, 16, false, sampler, viewTheta, "optimal");
  SceneOptions o = s.options;
  o.bankCacheDir = cacheDir;
  Scene scene = makeScene(o);
  cacheOptimalBank(scene);
  return scene;
}

std::string keyOf(const Scene& s) {
  return bankCacheKey(s.envmap, s.options.sampler, s.grid, flatMirror(s.geometry, "--envmap-pdf optimal"));
}

}  // namespace

TEST_CASE("a cached bank is the bank a build gives, bit for bit", "[bankcache][optimal]") {
  TempCache cache;
  for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf}) {
    const Scene built = smallScene("sun:40,90,0.5,1e5", "seed000", 16, 16, false, sampler, 0, "optimal");
    const Scene first = optimalScene("sun:40,90,0.5,1e5", "seed000", cache.path.string(), sampler);
    CHECK_FALSE(first.tables.bankFromCache);
    CHECK(fs::exists(bankCachePath(cache.path.string(), keyOf(first))));
    const Scene second = optimalScene("sun:40,90,0.5,1e5", "seed000", cache.path.string(), sampler);
    CHECK(second.tables.bankFromCache);
    checkSameTables(built.tables, first.tables);
    checkSameTables(built.tables, second.tables);
  }
}

TEST_CASE("a black map's bank, plain tables with empty bank arrays, is cached too", "[bankcache][optimal]") {
  TempCache cache;
  const Scene built = smallScene("constant:0", "seed000", 16, 16, false, EnvmapSampler::Alias, 0, "optimal");
  optimalScene("constant:0", "seed000", cache.path.string());
  const Scene second = optimalScene("constant:0", "seed000", cache.path.string());
  CHECK(second.tables.bankFromCache);
  checkSameTables(built.tables, second.tables);
}

TEST_CASE("the bank cache's key names everything the bank is built from", "[bankcache][optimal]") {
  TempCache cache;
  const std::string dir = cache.path.string();
  const std::string base = keyOf(optimalScene("cosk:2", "seed000", dir));
  CHECK(keyOf(optimalScene("cosk:2", "seed000", dir)) == base);
  CHECK(keyOf(optimalScene("cosk:4", "seed000", dir)) != base);                            // the map
  CHECK(keyOf(optimalScene("cosk:2", "uniform:0.2,0.8,50", dir)) != base);                 // the grid
  CHECK(keyOf(optimalScene("cosk:2", "seed000", dir, EnvmapSampler::Cdf)) != base);        // the sampler
  CHECK(keyOf(optimalScene("cosk:2", "seed000", dir, EnvmapSampler::Alias, 30)) != base);  // the view
  OptimalBankOptions coarser;
  coarser.blockLog2 = 4;
  const Scene s = optimalScene("cosk:2", "seed000", dir);
  CHECK(bankCacheKey(s.envmap, s.options.sampler, s.grid, flatMirror(s.geometry, "--envmap-pdf optimal"), coarser) !=
        base);  // the bank's options
}

TEST_CASE("makeScene reads the bank cache but writes nothing to it", "[bankcache][optimal]") {
  TempCache cache;
  Scene s = smallScene("cosk:2", "seed000", 16, 16, false, EnvmapSampler::Alias, 0, "optimal");
  SceneOptions o = s.options;
  o.bankCacheDir = cache.path.string();
  const Scene scene = makeScene(o);
  CHECK_FALSE(fs::exists(cache.path));
  cacheOptimalBank(scene);
  CHECK(fs::exists(bankCachePath(o.bankCacheDir, scene.bankCacheKey)));
  // A cache that cannot be written leaves the run alone.
  o.bankCacheDir = "/proc/no/cache";
  const Scene unwritable = makeScene(o);
  CHECK_NOTHROW(cacheOptimalBank(unwritable));
}

TEST_CASE("a damaged bank cache entry is rebuilt, never used", "[bankcache][optimal][bad-input]") {
  TempCache cache;
  const std::string dir = cache.path.string();
  const Scene built = smallScene("sun:40,90,0.5,1e5", "seed000", 16, 16, false, EnvmapSampler::Alias, 0, "optimal");
  const std::string path = bankCachePath(dir, keyOf(optimalScene("sun:40,90,0.5,1e5", "seed000", dir)));
  auto bytes = [&] {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  };
  const std::string good = bytes();
  auto damageWith = [&](const std::string& content) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << content;
    const Scene again = optimalScene("sun:40,90,0.5,1e5", "seed000", dir);
    CHECK_FALSE(again.tables.bankFromCache);
    checkSameTables(built.tables, again.tables);
    CHECK(bytes() == good);  // the entry is whole again
  };
  SECTION("a flipped byte") {
    std::string flipped = good;
    flipped[flipped.size() / 2] ^= 0x40;
    damageWith(flipped);
  }
  SECTION("a truncated file") { damageWith(good.substr(0, good.size() / 3)); }
  SECTION("an empty file") { damageWith(""); }
  SECTION("a FIFO, which an open to read would wait on") {
    std::filesystem::remove(path);
    REQUIRE(mkfifo(path.c_str(), 0600) == 0);
    const Scene again = optimalScene("sun:40,90,0.5,1e5", "seed000", dir);
    CHECK_FALSE(again.tables.bankFromCache);
    checkSameTables(built.tables, again.tables);
  }
  SECTION("another key's entry") {
    const Scene other = optimalScene("cosk:3", "seed000", dir);
    std::ifstream in(bankCachePath(dir, keyOf(other)), std::ios::binary);
    damageWith(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  }
}
