#include "distributions/BankCache.h"

#include <fmt/format.h>

#include <cstring>
#include <filesystem>
#include <iostream>
#include <optional>
#include <type_traits>
#include <variant>

#include "AtomicFile.h"
#include "ContentHash.h"
#include "WholeFile.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// Bumped whenever the tables or this layout change: older entries then miss.
constexpr char kMagic[8] = {'M', 'A', 'B', 'A', 'N', 'K', '0', '1'};

// The entry's bytes: plain values and length-prefixed vectors, in one order for both
// directions.
class Writer {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <typename T>
  void vector(const std::vector<T>& v) {
    value(uint64_t(v.size()));
    if (!v.empty()) bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  std::string& bytes() { return bytes_; }

 private:
  std::string bytes_;
};

// Reads bytes [at, end) of `bytes`.
class Reader {
 public:
  Reader(const std::string& bytes, size_t at, size_t end) : bytes_(bytes), at_(at), end_(end) {}
  template <typename T>
  void value(T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    take(&v, sizeof v);
  }
  template <typename T>
  void vector(std::vector<T>& v) {
    uint64_t n = 0;
    value(n);
    if (n > (end_ - at_) / sizeof(T)) throw std::runtime_error("a table longer than the file");
    v.resize(n);
    take(v.data(), n * sizeof(T));
  }
  bool atEnd() const { return at_ == end_; }

 private:
  void take(void* out, size_t n) {
    if (n > end_ - at_) throw std::runtime_error("the file ends early");
    if (n == 0) return;  // an empty table's data() may be null, which memcpy must not see
    std::memcpy(out, bytes_.data() + at_, n);
    at_ += n;
  }
  const std::string& bytes_;
  size_t at_, end_;
};

// Every field of the tables but the texels' RGB, which is the map's own (the caller's),
// through a Writer (const tables) or a Reader.
template <typename Io, typename Tables>
void transfer(Io& io, Tables& t, std::vector<float>& texelProbabilities) {
  io.value(t.width), io.value(t.height);
  io.vector(texelProbabilities), io.vector(t.cdfTable), io.vector(t.aliasTable);
  io.value(t.useCdf), io.value(t.cdfStepsRow), io.value(t.cdfStepsCol), io.value(t.uniformFallback);
  io.value(t.requestedPdf.kind), io.value(t.requestedPdf.envmapFraction);
  io.value(t.pdf.kind), io.value(t.pdf.envmapFraction);
  io.value(t.meanLuminance), io.value(t.zeroTexelFraction);
  io.value(t.bankShares), io.value(t.blockLog2), io.value(t.brdfBins);
  io.vector(t.blockProbs), io.vector(t.brdfBinOfPixel);
  io.value(t.bankVariances.compensatedOverOptimalMax), io.value(t.bankVariances.compensatedOverOptimalMean);
  io.value(t.bankVariances.entriesWithNegativeEq5);
}

uint64_t checksum(const char* data, size_t n) {
  ContentHash h;
  h.add(data, n);
  return h.h;
}

std::string encode(const std::string& key, const EnvmapTables& tables) {
  std::vector<float> probabilities(tables.texels.size() / 4);
  for (size_t t = 0; t < probabilities.size(); ++t) probabilities[t] = tables.texels[4 * t + 3];
  Writer w;
  w.bytes().append(kMagic, sizeof kMagic);
  w.bytes().append(key);
  transfer(w, tables, probabilities);
  w.value(checksum(w.bytes().data(), w.bytes().size()));
  return std::move(w.bytes());
}

// The tables of an entry that reads back whole, with the texels' RGB from `image`, else
// why not.
std::variant<EnvmapTables, std::string> decode(const std::string& bytes, const std::string& key,
                                               const RgbImage& image) {
  const size_t headerSize = sizeof kMagic + key.size();
  if (bytes.size() < headerSize + sizeof(uint64_t) || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return std::string("not a bank of this format");
  if (bytes.compare(sizeof kMagic, key.size(), key) != 0) return std::string("the entry of another key");
  const size_t body = bytes.size() - sizeof(uint64_t);
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + body, sizeof stored);
  if (stored != checksum(bytes.data(), body)) return std::string("its checksum does not match");
  EnvmapTables tables;
  try {
    Reader r(bytes, headerSize, body);
    std::vector<float> probabilities;
    transfer(r, tables, probabilities);
    if (!r.atEnd()) return std::string("bytes left over after the tables");
    if (probabilities.size() != image.rgb.size() / 3) return std::string("the tables of another map's size");
    tables.texels.resize(probabilities.size() * 4);
    for (size_t t = 0; t < probabilities.size(); ++t) {
      for (int c = 0; c < 3; ++c) tables.texels[4 * t + c] = image.rgb[3 * t + c];
      tables.texels[4 * t + 3] = probabilities[t];
    }
  } catch (const std::runtime_error& e) {
    return std::string(e.what());
  }
  return tables;
}

}  // namespace

std::string bankCacheKey(const Envmap& envmap, EnvmapSampler sampler, const BrdfGrid& grid,
                         const std::array<float, 3>& mirror, const OptimalBankOptions& options) {
  ContentHash h;
  h.addValue(envmap.image.width);
  h.addValue(envmap.image.height);
  h.addVector(envmap.image.rgb);
  h.addValue(sampler);
  h.addValue(grid.width);
  h.addValue(grid.height);
  h.addVector(grid.pixels);
  h.add(mirror.data(), sizeof mirror);
  h.addValue(options.exponentBins);
  h.addValue(options.diffuseBins);
  h.addValue(options.shares);
  h.addValue(options.blockLog2);
  return fmt::format("{:016x}", h.h);
}

std::string bankCachePath(const std::string& cacheDir, const std::string& key) {
  return (fs::path(cacheDir) / "banks" / (key + ".bin")).string();
}

std::optional<EnvmapTables> readCachedBank(const std::string& cacheDir, const std::string& key, const RgbImage& image) {
  const std::string path = bankCachePath(cacheDir, key);
  std::optional<std::string> bytes = readWholeFile(path);
  if (!bytes) return std::nullopt;
  auto decoded = decode(*bytes, key, image);
  if (auto* tables = std::get_if<EnvmapTables>(&decoded)) {
    tables->bankFromCache = true;
    return std::move(*tables);
  }
  std::cerr << fmt::format("misalloc: the optimal pdf's cached tables {} are damaged ({}); building them again\n", path,
                           std::get<std::string>(decoded));
  return std::nullopt;
}

void writeCachedBank(const std::string& cacheDir, const std::string& key, const EnvmapTables& tables) {
  const std::string path = bankCachePath(cacheDir, key);
  try {
    fs::create_directories(fs::path(path).parent_path());
    writeFileAtomically(path, encode(key, tables));
  } catch (const std::exception& e) {
    std::cerr << fmt::format("misalloc: the optimal pdf's tables were not cached: {}\n", e.what());
  }
}

}  // namespace misalloc
