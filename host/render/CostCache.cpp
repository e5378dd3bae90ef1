#include "render/CostCache.h"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <variant>

#include "AtomicFile.h"
#include "ContentHash.h"
#include "FileLock.h"
#include "WholeFile.h"
#include "render/Reference.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// Changed whenever the entries' contents, their key or what a calibration times change:
// older entries then miss. 2: stages launch only the pixels that take samples, and the
// calibration times those. 3: the calibration's launches sized by their samples
// (sampling/CostModel.cpp, calibrationSize).
constexpr char kFormat[] = "misalloc cost model 3";

// The envmap pdf's tables as the kernels read them, but the bank's bin of each pixel:
// a band's tables hold its own rows' bins, which the image's BRDFs (the scene's part of
// the key) decide.
void addTables(ContentHash& h, const EnvmapTables& t) {
  h.addValue(t.width);
  h.addValue(t.height);
  h.addVector(t.texels);
  h.addVector(t.cdfTable);
  h.addVector(t.aliasTable);
  h.addValue(t.useCdf);
  h.addValue(t.bankShares);
  h.addValue(t.blockLog2);
  h.addVector(t.blockProbs);
}

void addConfig(ContentHash& h, const SamplerConfig& c) {
  h.addValue(c.estimator);
  h.addValue(c.statsMask);
  h.addValue(c.sampleCapacity);
  h.addValue(c.gridSize);
  h.addValue(c.runningSums);
  h.addValue(c.shareColumns);
  h.addValue(c.risCandidates);
  h.addValue(c.optimalWeights);
}

nlohmann::json kernelJson(const CostModel::KernelCosts& k) {
  return {{"per_launch_s", k.perLaunch}, {"per_sample_s", k.perSample}, {"launches", k.launches}};
}

// One kernel's costs as fitted: finite, none negative, every c_k positive where the
// kernel was calibrated at all (a sampler without statistics has no such kernel).
std::optional<CostModel::KernelCosts> kernelCosts(const nlohmann::json& j, int techniques) {
  CostModel::KernelCosts k;
  k.perLaunch = j.at("per_launch_s").get<double>();
  k.perSample = j.at("per_sample_s").get<std::vector<double>>();
  k.launches = j.at("launches").get<int>();
  if (int(k.perSample.size()) != techniques || k.launches < 0 || !std::isfinite(k.perLaunch) || k.perLaunch < 0)
    return std::nullopt;
  for (double c : k.perSample)
    if (!std::isfinite(c) || c < 0 || (k.launches > 0 && c == 0)) return std::nullopt;
  return k;
}

std::string checksumOf(const nlohmann::json& body) {
  ContentHash h;
  h.add(body.dump());
  return fmt::format("{:016x}", h.h);
}

std::string encode(const std::string& key, const StageSampler& sampler, const CostModel& model) {
  nlohmann::json body = {
      {"format", kFormat},
      {"key", key},
      {"launch_identity", sampler.launchIdentity()},
      {"techniques", sampler.scene().techniqueNames()},
      {"kernels",
       {{"plain", kernelJson(model.kernelCosts(false))}, {"with_statistics", kernelJson(model.kernelCosts(true))}}}};
  nlohmann::json entry = body;
  entry["checksum"] = checksumOf(body);
  return entry.dump(2) + "\n";
}

// The model of an entry that reads back whole, else why not.
std::variant<CostModel, std::string> decode(const std::string& text, const std::string& key, int techniques) {
  try {
    nlohmann::json entry = nlohmann::json::parse(text);
    if (!entry.is_object() || entry.value("format", "") != kFormat) return std::string("not an entry of this format");
    const std::string checksum = entry.at("checksum").get<std::string>();
    entry.erase("checksum");
    if (checksum != checksumOf(entry)) return std::string("its checksum does not match");
    if (entry.at("key").get<std::string>() != key) return std::string("the entry of another key");
    const nlohmann::json& kernels = entry.at("kernels");
    auto plain = kernelCosts(kernels.at("plain"), techniques);
    auto statistics = kernelCosts(kernels.at("with_statistics"), techniques);
    if (!plain || !statistics || plain->launches == 0) return std::string("costs that are not a calibration's");
    return CostModel::cached(std::move(*plain), std::move(*statistics));
  } catch (const nlohmann::json::exception& e) {
    return fmt::format("it does not parse: {}", e.what());
  }
}

// The entry's model where the file exists and reads back whole; a damaged one is named
// on stderr unless `quiet`.
std::optional<CostModel> readEntry(const std::string& path, const std::string& key, int techniques, bool quiet) {
  std::error_code error;
  if (!fs::exists(path, error)) return std::nullopt;
  const std::optional<std::string> text = readWholeFile(path);
  if (!text) {
    if (!quiet)
      std::cerr << fmt::format(
          "misalloc: the cached costs {} are not a readable regular file; calibrating them again\n", path);
    return std::nullopt;
  }
  auto decoded = decode(*text, key, techniques);
  if (auto* model = std::get_if<CostModel>(&decoded)) return std::move(*model);
  if (!quiet)
    std::cerr << fmt::format("misalloc: the cached costs {} are damaged ({}); calibrating them again\n", path,
                             std::get<std::string>(decoded));
  return std::nullopt;
}

// The lock under which one of the runs that share a cache calibrates the entry at
// `path`; throws InputError where the cache's folders cannot be made or locked.
std::unique_ptr<FileLock> calibrationLock(const std::string& cacheDir, const std::string& key,
                                          const std::string& path) {
  const fs::path lockPath = fs::path(cacheDir) / "locks" / ("costs-" + key + ".lock");
  for (const fs::path& folder : {fs::path(path).parent_path(), lockPath.parent_path()}) {
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec) throw InputError(fmt::format("cannot create {}: {}", folder.string(), ec.message()));
  }
  return std::make_unique<FileLock>(lockPath.string(), [&] {
    std::cerr << fmt::format("misalloc: another process is calibrating the costs {}; waiting for it\n", path)
              << std::flush;
  });
}

void warnNotCached(const std::string& why) {
  std::cerr << fmt::format(
      "misalloc: warning: the calibrated costs were not cached ({}): this render's allocations are not "
      "repeatable\n",
      why);
}

}  // namespace

std::string costCacheKey(const StageSampler& sampler, const Scene& image) {
  ContentHash h;
  h.add(kFormat);
  h.add(sampler.launchIdentity());
  addConfig(h, sampler.config());
  for (const std::string& name : sampler.scene().techniqueNames()) h.add(name);
  addTables(h, sampler.scene().tables);
  addTables(h, sampler.scene().pilotTables);
  const ProductTables& product = sampler.scene().productTables;
  h.addValue(product.tables);
  h.addValue(product.pixelCells);
  h.addVector(product.floats);
  h.addVector(product.words);
  // The image's map, size, view, frames and BRDFs, as its reference is keyed.
  h.add(referenceKey(image, 0));
  return fmt::format("{:016x}", h.h);
}

std::string costCachePath(const std::string& cacheDir, const std::string& key) {
  return (fs::path(cacheDir) / "costs" / (key + ".json")).string();
}

void provideCostModel(StageSampler& sampler, const Scene& image, const CostCacheRequest& request) {
  if (request.cacheDir.empty()) {
    sampler.setCostModel(calibrateCostModel(sampler));
    return;
  }
  const std::string key = costCacheKey(sampler, image), path = costCachePath(request.cacheDir, key);
  const int techniques = sampler.scene().techniqueCount();
  // Read without the lock first: a hit, the common case, never waits for another run.
  if (!request.measure)
    if (auto cached = readEntry(path, key, techniques, true)) {
      sampler.setCostModel(std::move(*cached));
      return;
    }
  std::unique_ptr<FileLock> lock;
  try {
    lock = calibrationLock(request.cacheDir, key, path);
  } catch (const InputError& e) {
    warnNotCached(e.what());
    sampler.setCostModel(calibrateCostModel(sampler));
    return;
  }
  if (!request.measure)
    if (auto cached = readEntry(path, key, techniques, false)) {
      sampler.setCostModel(std::move(*cached));
      return;
    }
  CostModel model = calibrateCostModel(sampler);
  try {
    writeFileAtomically(path, encode(key, sampler, model));
  } catch (const InputError& e) {
    warnNotCached(e.what());
  }
  sampler.setCostModel(std::move(model));
}

}  // namespace misalloc
