// misalloc merge: the bands of a sharded render (render --shard K/N) joined into the
// image the unsharded render writes, bit for bit, with a report of where and how long
// each band ran; or the shards of a comparison (compare --shard K/N) joined into the
// folder the unsharded comparison writes.
#include <fmt/format.h>

#include <iostream>
#include <memory>

#include "Error.h"
#include "Interruption.h"
#include "JsonText.h"
#include "OutputSet.h"
#include "cli/Subcommand.h"
#include "compare/CompareReport.h"
#include "compare/ShardMerge.h"
#include "compare/SummaryTables.h"
#include "render/BandFile.h"
#include "scene/ExrIO.h"

namespace misalloc {
namespace {

struct MergeArgs {
  std::string out, report = "merged.json", outDir;
  std::vector<std::string> parts;  // bands or shard folders
};

int mergeRender(const MergeArgs& args) {
  exitOnInterrupt();
  std::vector<NamedFile> inputs;
  for (const std::string& band : args.parts) inputs.push_back({"a band", band});
  OutputSet outputs(inputs);
  outputs.claim("--out", args.out);
  outputs.claim("--report", args.report);
  MergedRender merged = mergeBands(args.parts);
  outputs.put(args.out, encodeExr(merged.image));  // the writer of the unsharded render
  outputs.put(args.report, jsonText(merged.report));
  outputs.commit();
  std::cout << fmt::format("merged {} band(s) into {} ({}x{}); wrote {}\n", args.parts.size(), args.out,
                           merged.image.width, merged.image.height, args.report);
  return 0;
}

int mergeComparison(const MergeArgs& args) {
  exitOnInterrupt();
  std::vector<NamedFile> inputs;
  for (const std::string& shard : args.parts) inputs.push_back({"a shard", shard});
  OutputSet outputs(inputs);
  const std::string staging = outputs.claimFolder("--out-dir", args.outDir, "runs.json");
  MergedComparison merged = mergeShards(args.parts);
  for (const std::string& shard : args.parts) copyShardFiles(shard, staging);
  // The writers of the unsharded compare, on the runs as the shards measured them.
  writeRuns(staging, merged.comparison);
  ComparisonReport report = writeComparisonReport(merged.comparison, merged.options, staging);
  outputs.commit();
  std::cout << summaryMarkdown(report.summary) << report.envmapPdfTables << report.weightsTables;
  std::cout << fmt::format(
      "\nmerged {} shard(s) into {}: index.html, summary.{{md,csv,json}}, budgets.csv, "
      "runs.{{json,csv}}\n",
      args.parts.size(), args.outDir);
  return 0;
}

int runMerge(const MergeArgs& args) {
  if (args.out.empty() == args.outDir.empty())
    throw InputError(
        "merge: give --out FILE.exr for the bands of a sharded render, or --out-dir DIR for the shards "
        "of a comparison");
  return args.out.empty() ? mergeComparison(args) : mergeRender(args);
}

}  // namespace

Subcommand addMergeCommand(CLI::App& app) {
  auto* command = app.add_subcommand(
      "merge", "join the bands of a sharded render (--out) or the shards of a comparison (--out-dir)");
  auto args = std::make_shared<MergeArgs>();
  command->add_option("--out", args->out, "the merged EXR of a sharded render's bands");
  command->add_option("--out-dir", args->outDir, "the merged folder of a sharded comparison's shards");
  command->add_option("--report", args->report, "the merged JSON report: each band's rows, node, times and report")
      ->capture_default_str();
  command->add_option("parts", args->parts, "the bands' EXR files or the shards' folders, each once, in any order")
      ->required();
  return {command, [args] { return runMerge(*args); }};
}

}  // namespace misalloc
