#include "render/BandFile.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <climits>
#include <map>

#include "Error.h"

namespace misalloc {
namespace {

const std::string kRun = "misalloc.band.run", kShard = "misalloc.band.shard", kRows = "misalloc.band.rows",
                  kImage = "misalloc.band.image", kNode = "misalloc.band.node", kReport = "misalloc.band.report";

// A band as read back, its record checked for the keys a band has.
struct ReadBand {
  std::string path;
  RgbImage rows;
  BandRecord record;
};

std::string attribute(const ExrAttributes& found, const std::string& name, const std::string& path) {
  auto it = found.find(name);
  if (it == found.end())
    throw InputError(
        fmt::format("{}: not a band of a sharded render (misalloc render --shard): it has no {}", path, name));
  return it->second;
}

ReadBand readBand(const std::string& path) {
  ExrAttributes found;
  ReadBand band{path, readExr(path, nullptr, &found), {}};
  BandRecord& r = band.record;
  r.run = attribute(found, kRun, path);
  r.node = attribute(found, kNode, path);
  const std::string shard = attribute(found, kShard, path), rows = attribute(found, kRows, path),
                    image = attribute(found, kImage, path);
  r.report = nlohmann::json::parse(attribute(found, kReport, path), nullptr, false);
  const Shard& k = r.band.shard;
  const RowRange& y = r.band.rows;
  if (std::sscanf(shard.c_str(), "%d/%d", &r.band.shard.index, &r.band.shard.count) != 2 ||
      std::sscanf(rows.c_str(), "%d-%d", &r.band.rows.begin, &r.band.rows.end) != 2 ||
      std::sscanf(image.c_str(), "%dx%d", &r.width, &r.height) != 2 || k.index < 0 || k.index >= k.count ||
      y.begin < 0 || y.begin >= y.end || y.end > r.height || r.report.is_discarded())
    throw InputError(
        fmt::format("{}: its band record is malformed (shard {}, rows {}, image {})", path, shard, rows, image));
  if (band.rows.width != r.width || band.rows.height != r.band.rows.size())
    throw InputError(fmt::format("{}: its pixels are {}x{}, not the {}x{} of rows {} of a {} image", path,
                                 band.rows.width, band.rows.height, r.width, r.band.rows.size(), rows, image));
  return band;
}

// Refuses bands that are not exactly one run's N bands, each once, tiling its rows.
void requireOneRun(std::vector<ReadBand>& bands) {
  const BandRecord& first = bands.front().record;
  std::sort(bands.begin(), bands.end(),
            [](const ReadBand& a, const ReadBand& b) { return a.record.band.shard.index < b.record.band.shard.index; });
  for (const ReadBand& b : bands) {
    const BandRecord& r = b.record;
    if (r.run != first.run)
      throw InputError(fmt::format("{} and {} are bands of different runs: {}", bands.front().path, b.path,
                                   runDifference(first.run, r.run)));
    if (r.width != first.width || r.height != first.height || r.band.shard.count != first.band.shard.count)
      throw InputError(
          fmt::format("{} and {} are bands of different images or shard counts", bands.front().path, b.path));
  }
  int nextRow = 0;
  for (size_t i = 0; i < bands.size(); ++i) {
    const BandRecord& r = bands[i].record;
    if (i > 0 && r.band.shard.index == bands[i - 1].record.band.shard.index)
      throw InputError(fmt::format("{} and {} are the same band, {}/{}", bands[i - 1].path, bands[i].path,
                                   r.band.shard.index, r.band.shard.count));
    if (r.band.rows.begin != nextRow)
      throw InputError(
          fmt::format("{}: its rows {}-{} do not follow row {} of the bands before it: a band {} or "
                      "overlapping",
                      bands[i].path, r.band.rows.begin, r.band.rows.end, nextRow,
                      r.band.rows.begin > nextRow ? "is missing" : "is given twice"));
    nextRow = r.band.rows.end;
  }
  if (int(bands.size()) != first.band.shard.count || nextRow != first.height)
    throw InputError(fmt::format("{} band(s) of {} given: rows {} to {} are missing", bands.size(),
                                 first.band.shard.count, nextRow, first.height));
}

}  // namespace

std::string encodeBand(const RgbImage& rows, const BandRecord& record) {
  const Band& b = record.band;
  return encodeExr(rows, {{kRun, record.run},
                          {kShard, fmt::format("{}/{}", b.shard.index, b.shard.count)},
                          {kRows, fmt::format("{}-{}", b.rows.begin, b.rows.end)},
                          {kImage, fmt::format("{}x{}", record.width, record.height)},
                          {kNode, record.node},
                          {kReport, record.report.dump()}});
}

MergedRender mergeBands(const std::vector<std::string>& paths) {
  std::vector<ReadBand> bands;
  for (const std::string& path : paths) bands.push_back(readBand(path));
  requireOneRun(bands);
  const BandRecord& first = bands.front().record;
  MergedRender merged{RgbImage{first.width, first.height, {}, {}}, {{"run", first.run}}};
  nlohmann::json records = nlohmann::json::array();
  for (const ReadBand& b : bands) {
    merged.image.rgb.insert(merged.image.rgb.end(), b.rows.rgb.begin(), b.rows.rgb.end());
    const Band& band = b.record.band;
    records.push_back({{"file", b.path},
                       {"shard", fmt::format("{}/{}", band.shard.index, band.shard.count)},
                       {"rows", {band.rows.begin, band.rows.end}},
                       {"node", b.record.node},
                       {"report", b.record.report}});
  }
  // A band with no background pixel has no alpha of its own.
  if (std::any_of(bands.begin(), bands.end(), [](const ReadBand& b) { return !b.rows.alpha.empty(); }))
    for (const ReadBand& b : bands) {
      const std::vector<float> opaque(size_t(b.rows.width) * b.rows.height, 1.0f);
      const std::vector<float>& a = b.rows.alpha.empty() ? opaque : b.rows.alpha;
      merged.image.alpha.insert(merged.image.alpha.end(), a.begin(), a.end());
    }
  merged.report["size"] = {first.width, first.height};
  merged.report["bands"] = std::move(records);
  return merged;
}

std::string nodeName() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) != 0) return "unknown";
  return name;
}

}  // namespace misalloc
