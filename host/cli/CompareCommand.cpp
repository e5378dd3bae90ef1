// misalloc compare: error against time for methods × budgets × repeats on one scene or
// the suite, with equal-time tables, plots and index.html.
#include <fmt/format.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "AtomicFile.h"
#include "Error.h"
#include "NumberList.h"
#include "OptionRange.h"
#include "OutputSet.h"
#include "cli/AdaptiveArgs.h"
#include "cli/DeviceArgs.h"
#include "cli/RunIdentity.h"
#include "cli/SceneArgs.h"
#include "cli/SceneInputs.h"
#include "cli/StatisticsMemory.h"
#include "cli/Subcommand.h"
#include "compare/CompareReport.h"
#include "compare/Comparison.h"
#include "compare/EnvmapPdfComparison.h"
#include "compare/ShardFiles.h"
#include "compare/ShardRecord.h"
#include "compare/ShardUnit.h"
#include "compare/Suite.h"
#include "compare/Summary.h"
#include "compare/SummaryTables.h"
#include "compare/WeightsComparison.h"
#include "render/Reference.h"
#include "render/RunChecks.h"

namespace misalloc {
namespace {

struct CompareArgs {
  CLI::App* command = nullptr;
  SceneArgs scene;
  AdaptiveArgs adaptive;
  DeviceArgs devices;
  CompareOptions compare;
  std::string methods = "all", budgets = "50,100,200,400,800", envmapPdfs = "plain,optimal", weights = "balance", shard;
  std::string shardUnit = "scene";
  bool suite = false;
};

// "all" or a comma-separated list of method names, each once.
std::vector<Method> parseMethodList(const std::string& list) {
  if (list == "all") return allMethods();
  std::vector<Method> methods;
  std::stringstream items(list);
  for (std::string item; std::getline(items, item, ',');) {
    Method m = parseMethod(item);
    if (std::find(methods.begin(), methods.end(), m) != methods.end())
      throw InputError(fmt::format("--methods {}: {} is listed twice", list, item));
    methods.push_back(m);
  }
  return methods;
}

std::vector<int> parseBudgets(const std::string& list) {
  std::vector<int> budgets;
  for (double v : parseNumberList("--budgets", list, list, 0, "expected spp,spp,... in ascending order")) {
    if (v != std::floor(v) || v < 1 || v > 1e7)
      throw InputError(fmt::format("--budgets {}: {} is not a whole number of samples per pixel", list, v));
    budgets.push_back(int(v));
  }
  return budgets;
}

// The lists as parsed, in one spelling, written back to their options' variables, which
// a shard's run identity reads (cli/RunIdentity.h): `--methods all` and the list of its
// methods, `--budgets 16.0` and `16`, are one run.
void writeBackLists(CompareArgs& args, const CompareOptions& compare, const std::vector<EnvmapPdf>& pdfs,
                    const std::vector<MisWeights>& weights) {
  std::vector<std::string> methods, pdfNames, weightNames;
  for (Method m : compare.methods) methods.push_back(methodName(m));
  for (const EnvmapPdf& pdf : pdfs) pdfNames.push_back(envmapPdfName(pdf));
  for (MisWeights w : weights) weightNames.push_back(misWeightsName(w));
  args.methods = fmt::format("{}", fmt::join(methods, ","));
  args.budgets = fmt::format("{}", fmt::join(compare.budgets, ","));
  args.envmapPdfs = fmt::format("{}", fmt::join(pdfNames, ","));
  args.weights = fmt::format("{}", fmt::join(weightNames, ","));
}

int runCompare(CompareArgs& args) {
  InterruptionGuard guard;  // first: every thread started from here on inherits its mask
  CompareOptions& compare = args.compare;
  // The probe below is a plain scene (compare takes its pdfs from --envmap-pdfs), but on
  // per-pixel geometry the product exists only with the optimal pdf per pixel's cells.
  if (args.scene.parsed().productNeedsPixelCells()) args.scene.envmapPdf = "optimal-pixel";
  if (args.suite) {
    for (const char* sceneOption : {"--envmap", "--grid", "--envmap-sampler", "--split-brdf"})
      if (args.command->count(sceneOption) > 0)
        throw InputError(fmt::format("--suite runs its own scenes: drop {}", sceneOption));
    if (args.command->count("--size") == 0) args.scene.size = "64x64";
    Scene probe = args.scene.make();  // checks --size and --view
    for (CompareCase c : suiteCases(probe.grid.width, probe.grid.height)) {
      c.scene.shape = probe.options.shape;
      c.scene.gbuffer = probe.options.gbuffer;
      c.scene.mesh = probe.options.mesh;
      c.scene.viewTheta = probe.options.viewTheta;
      c.scene.viewPhi = probe.options.viewPhi;
      c.scene.product = probe.options.product;  // the suite with the product technique in every case
      compare.cases.push_back(c);
    }
  } else {
    Scene probe = args.scene.make();  // reads the envmap once, so bad input fails before any work
    compare.cases.push_back({caseLabel(probe.options), probe.options, {}, {}});
    // The optimal pdf's bank has no split lobes: the default is then the plain pdf alone.
    if (probe.options.splitBrdf && args.command->count("--envmap-pdfs") == 0) args.envmapPdfs = "plain";
  }
  // Nor per-pixel normals and views: each pixel's own optimal pdf stands in, and alone
  // where the product technique comes from its cells.
  const SceneOptions& first = compare.cases.front().scene;
  if (first.perPixelGeometry() && args.command->count("--envmap-pdfs") == 0 && !first.splitBrdf)
    args.envmapPdfs = first.productNeedsPixelCells() ? "optimal-pixel" : "plain,optimal-pixel";
  const std::vector<EnvmapPdf> pdfs = parseEnvmapPdfList(args.envmapPdfs);
  for (const EnvmapPdf& pdf : pdfs)
    if (first.productNeedsPixelCells() && !pdf.pixelOptimal())
      throw InputError(fmt::format(
          "--product with --envmap-pdfs {} on per-pixel normals or views: not implemented; only optimal-pixel "
          "builds the product there, from each pixel's cells",
          envmapPdfName(pdf)));
  const std::vector<MisWeights> weights = parseWeightsList(args.weights);
  const ShardUnit unit = parseShardUnit(args.shardUnit, "--shard-unit");
  compare.methods = parseMethodList(args.methods);
  // envmap, brdf and ris never sample the product technique: with --product, "all" is the others.
  if (args.methods == "all" && compare.cases.front().scene.product)
    compare.methods.erase(std::remove_if(compare.methods.begin(), compare.methods.end(),
                                         [](Method m) { return !takesProductTechnique(m); }),
                          compare.methods.end());
  compare.budgets = parseBudgets(args.budgets);
  // Every scene with every pdf and then every weights; methods refused with the default
  // pdfs or with optimal weights are left out of those cases alone, saying why.
  auto variants = [&](const std::vector<CompareCase>& scenes) {
    std::vector<CompareCase> cases = casesPerEnvmapPdf(scenes, pdfs);
    if (args.command->count("--envmap-pdfs") == 0)
      leaveOutBiasedMethods(cases, compare.methods, compare.budgets, compare.adaptive);
    return casesPerWeights(cases, weights, compare.methods, compare.budgets, compare.adaptive);
  };
  // The reference's own variance, about that of a render of as many samples with the
  // best estimator, stays within 2 % of the smallest error at the largest budget (an
  // adaptive method may beat that estimator by 10–20 % per sample).
  if (args.command->count("--reference-spp") == 0)
    compare.referenceSpp = std::max(compare.referenceSpp, 64 * compare.budgets.back());
  compare.adaptive = args.adaptive.make(compare.cases.front().scene.techniqueCount());
  std::optional<ShardRecord> shard;
  if (!args.shard.empty()) {
    // Every shard knows the whole run's cases, in order, for the merge; the merge
    // checks the unit itself, to name it when shards of two units meet.
    shard.emplace();
    writeBackLists(args, compare, pdfs, weights);
    std::vector<SceneOptions> scenes;
    for (const CompareCase& c : compare.cases) scenes.push_back(c.scene);
    shard->run = runIdentity(*args.command, {"--shard", "--shard-unit", "--out-dir", "--cache-dir", "--help"}, scenes);
    shard->shard = parseShard(args.shard, "--shard");
    shard->unit = unit;
    for (const CompareCase& c : variants(compare.cases)) shard->manifest.push_back(c.label);
  }
  compare.cases = shardCases(compare.cases, compare.repeats, unit, shard ? shard->shard : Shard{});
  compare.cases = variants(compare.cases);
  for (CompareCase& c : compare.cases) c.scene.bankCacheDir = compare.cacheDir;
  compare.device = args.devices.spec();
  validateCompareOptions(compare);
  for (const CompareCase& c : compare.cases) {
    AdaptiveOptions adaptive = compare.adaptive;
    adaptive.weights = c.weights;
    for (int budget : compare.budgets)
      requireStatisticsMemory(c.scene, caseMethods(c, compare.methods), "--budgets", budget, adaptive,
                              args.devices.onHost(), args.devices.samplerCount());
  }
  std::vector<SceneOptions> scenes;
  for (const CompareCase& c : compare.cases) scenes.push_back(c.scene);
  std::vector<NamedFile> inputs = sceneInputs(scenes);
  inputs.push_back({"--cache-dir", compare.cacheDir});
  OutputSet outputs(inputs);
  const std::string outDir = compare.outDir;
  // Filled as it runs, and put in the place of the folder at the end.
  compare.outDir = outputs.claimFolder("--out-dir", outDir, "runs.json");
  Comparison comparison = runComparison(compare, guard);
  if (shard) {
    // A shard's summary would compare its own scenes only: merge writes the run's.
    shard->methods = compare.methods;
    shard->budgets = compare.budgets;
    shard->repeats = compare.repeats;
    shard->tableBudget = compare.tableBudget;
    shard->comparison = comparison;
    shard->files = shardFileChecksums(compare.outDir);
    writeFileAtomically(compare.outDir + "/" + kShardRecordFile, shardRecordJson(*shard));
    outputs.commit();
    std::cout << fmt::format("shard {}: {} case(s), {} run(s) in {}; merge the shards with misalloc merge --out-dir\n",
                             args.shard, comparison.cases.size(), comparison.runs.size(), outDir);
    return comparison.interrupted ? 130 : 0;
  }
  ComparisonReport report = writeComparisonReport(comparison, compare, compare.outDir);
  outputs.commit();
  if (comparison.interrupted) {
    std::cerr << fmt::format("misalloc: interrupted after {} runs; {} holds them, every file complete\n",
                             comparison.runs.size(), outDir);
    return 130;
  }
  std::cout << summaryMarkdown(report.summary) << report.envmapPdfTables << report.weightsTables;
  std::cout << fmt::format("\nwrote {}/index.html, summary.{{md,csv,json}}, budgets.csv, runs.{{json,csv}}\n", outDir);
  return 0;
}

}  // namespace

Subcommand addCompareCommand(CLI::App& app) {
  auto args = std::make_shared<CompareArgs>();
  auto* command = args->command = app.add_subcommand(
      "compare", "error against time: methods x budgets x repeats, equal-time tables, plots and index.html");
  CompareOptions& compare = args->compare;
  args->scene.add(*command);
  args->adaptive.add(*command);
  command->add_flag("--suite", args->suite,
                    "every shipped envmap x seed000 plus forest_slope with the cdf sampler, at 64x64 unless --size");
  command->add_option("--methods", args->methods, "comma-separated methods, or all")->capture_default_str();
  command->add_option("--budgets", args->budgets, "samples per pixel, ascending")->capture_default_str();
  command
      ->add_option(
          "--envmap-pdfs", args->envmapPdfs,
          "envmap pdfs, each scene runs with each: plain, compensated[:C], optimal, optimal-pixel (default: plain and "
          "optimal side by side; plain alone with --split-brdf; plain and optimal-pixel on spheres, G-buffers and "
          "meshes)")
      ->capture_default_str();
  command
      ->add_option("--weights", args->weights,
                   "MIS weights, each scene and pdf runs with each: balance, optimal ([Kon19]; render --weights)")
      ->capture_default_str();
  command->add_option("--repeats", compare.repeats, "independent seeds per method and budget")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  command->add_option("--seed", compare.seed, "repeat r uses seed + r")->capture_default_str()->check(anyUnsigned64());
  command->add_option("--table-spp", compare.tableBudget, "the budget of the Table 5.2 layout (nearest one run)")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  command->add_option("--out-dir", compare.outDir, "output folder (created if missing)")->required();
  args->devices.add(*command, "comma-separated: auto, cpu, gpu, an index, host (C++), all, or D:N (sub-devices)");
  command->add_option("--local-size", compare.localSize, kLocalSizeHelp)->check(integerIn(1, INT_MAX));
  command
      ->add_option("--reference-spp", compare.referenceSpp,
                   "spp of a sampled reference (default: 64 x the largest budget, at least 16384)")
      ->check(integerIn(1, INT_MAX));
  compare.cacheDir = defaultCacheDir();
  command->add_option("--cache-dir", compare.cacheDir, "where references and the optimal pdf's tables are cached")
      ->capture_default_str();
  auto* shardOption = command->add_option(
      "--shard", args->shard,
      "K/N: run shard K of N (every N-th unit of --shard-unit) into --out-dir, for `misalloc merge --out-dir`");
  command
      ->add_option("--shard-unit", args->shardUnit,
                   "with --shard: scene (a scene's methods, pdfs, budgets and repeats in one shard) or repeat (a "
                   "scene's repeat with all its methods, pdfs and budgets)")
      ->capture_default_str()
      ->needs(shardOption);
  return {command, [args] { return runCompare(*args); }};
}

}  // namespace misalloc
