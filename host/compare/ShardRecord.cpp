#include "compare/ShardRecord.h"

#include <fmt/format.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "Error.h"
#include "JsonText.h"
#include "report/Report.h"

namespace misalloc {
namespace {

// Every field, as a double keeps it: merge rebuilds the runs the shards measured.
nlohmann::json runRecordJson(const RunRecord& r) {
  return {{"case", r.caseLabel},
          {"method", methodName(r.method)},
          {"budget", r.budget},
          {"repeat", r.repeat},
          {"seed", r.seed},
          {"node", r.node},
          {"seconds", {r.wallSeconds, r.kernelSeconds, r.allocationSeconds, r.hostSeconds}},
          {"mse", {r.mse, r.mseStandardError, r.rawMse, r.relativeMse}},
          {"mean_alpha", r.meanAlpha},
          {"fractions", {r.fallbackFraction, r.flooredFraction, r.skippedFraction, r.weightsFallbackFraction}},
          {"statistics_bytes_per_pixel", r.statisticsBytesPerPixel},
          {"costs_source", r.costSource},
          {"predicted_gain", optionalJson(r.predictedGain)},
          {"kept_equal_counts", r.keptEqualCounts},
          {"stages", stagesJson(r.stages)}};
}

RunRecord runRecordOf(const nlohmann::json& j) {
  RunRecord r;
  r.caseLabel = j.at("case");
  r.method = parseMethod(j.at("method"));
  r.budget = j.at("budget");
  r.repeat = j.at("repeat");
  r.seed = j.at("seed");
  r.node = j.at("node");
  const auto& s = j.at("seconds");
  r.wallSeconds = s.at(0), r.kernelSeconds = s.at(1), r.allocationSeconds = s.at(2), r.hostSeconds = s.at(3);
  const auto& e = j.at("mse");
  r.mse = e.at(0), r.mseStandardError = e.at(1), r.rawMse = e.at(2), r.relativeMse = e.at(3);
  r.meanAlpha = j.at("mean_alpha").get<std::vector<double>>();
  const auto& f = j.at("fractions");
  r.fallbackFraction = f.at(0), r.flooredFraction = f.at(1), r.skippedFraction = f.at(2);
  r.weightsFallbackFraction = f.at(3);
  r.statisticsBytesPerPixel = j.at("statistics_bytes_per_pixel");
  r.costSource = j.at("costs_source");
  if (j.contains("predicted_gain") && !j.at("predicted_gain").is_null())
    r.predictedGain = j.at("predicted_gain").get<double>();
  r.keptEqualCounts = j.value("kept_equal_counts", false);
  for (const auto& s : j.at("stages")) {
    StageTiming t;
    t.samples = s.at("samples");
    t.keptStatistics = s.at("keeps_statistics");
    t.kernelSeconds = s.at("kernel_s");
    if (s.contains("predicted_kernel_s")) t.predictedKernelSeconds = s.at("predicted_kernel_s").get<double>();
    r.stages.push_back(t);
  }
  return r;
}

CaseInfo caseInfoOf(const nlohmann::json& j) {
  std::vector<LeftOutMethod> leftOut;
  for (const auto& l : j.at("left_out")) leftOut.push_back({parseMethod(l.at("method")), l.at("why")});
  return {j.at("label"),
          j.at("scene"),
          j.at("techniques").get<std::vector<std::string>>(),
          j.at("costs_s_per_sample").get<std::vector<double>>(),
          j.at("costs_source"),
          j.at("reference"),
          j.at("reference_variance"),
          j.at("device"),
          leftOut,
          j.at("repeats").get<std::vector<int>>(),
          parseMisWeights(j.at("weights"), "a shard's weights")};
}

}  // namespace

std::string shardRecordJson(const ShardRecord& record) {
  nlohmann::json methods = nlohmann::json::array(), cases = nlohmann::json::array(), runs = nlohmann::json::array();
  for (Method m : record.methods) methods.push_back(methodName(m));
  for (const CaseInfo& c : record.comparison.cases) cases.push_back(caseInfoJson(c));
  for (const RunRecord& r : record.comparison.runs) runs.push_back(runRecordJson(r));
  return jsonText({{"run", record.run},
                   {"shard", {record.shard.index, record.shard.count}},
                   {"unit", shardUnitName(record.unit)},
                   {"manifest", record.manifest},
                   {"methods", methods},
                   {"budgets", record.budgets},
                   {"repeats", record.repeats},
                   {"table_spp", record.tableBudget},
                   {"interrupted", record.comparison.interrupted},
                   {"cases", cases},
                   {"runs", runs},
                   {"files", record.files}});
}

ShardRecord readShardRecord(const std::string& folder) {
  const std::filesystem::path path = std::filesystem::path(folder) / kShardRecordFile;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw InputError(
        fmt::format("{}: not a shard of a comparison (compare --shard): it has no {}", folder, kShardRecordFile));
  // A FIFO would block the read, a folder read as empty.
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(fmt::format("{}: not a regular file", path.string()));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot be read", path.string()));
  try {
    const nlohmann::json j = nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
    ShardRecord r;
    r.run = j.at("run");
    r.shard = {j.at("shard").at(0), j.at("shard").at(1)};
    if (r.shard.index < 0 || r.shard.index >= r.shard.count)
      throw InputError(
          fmt::format("{}: its {} names shard {}/{}", folder, kShardRecordFile, r.shard.index, r.shard.count));
    r.unit = parseShardUnit(j.at("unit"), fmt::format("{}: its {}'s unit", folder, kShardRecordFile));
    r.manifest = j.at("manifest").get<std::vector<std::string>>();
    for (const auto& m : j.at("methods")) r.methods.push_back(parseMethod(m));
    r.budgets = j.at("budgets").get<std::vector<int>>();
    r.repeats = j.at("repeats");
    if (r.repeats < 1)
      throw InputError(fmt::format("{}: its {} names {} repeats", folder, kShardRecordFile, r.repeats));
    r.tableBudget = j.at("table_spp");
    r.comparison.interrupted = j.at("interrupted");
    for (const auto& c : j.at("cases")) r.comparison.cases.push_back(caseInfoOf(c));
    for (const auto& run : j.at("runs")) r.comparison.runs.push_back(runRecordOf(run));
    r.files = j.at("files").get<std::map<std::string, std::string>>();
    return r;
  } catch (const nlohmann::json::exception& e) {
    throw InputError(fmt::format("{}: its {} cannot be read: {}", folder, kShardRecordFile, e.what()));
  }
}

}  // namespace misalloc
