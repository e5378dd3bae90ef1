// misalloc: per-pixel MIS sample allocation for envmap × BRDF direct lighting.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include "AtomicFile.h"
#include "Error.h"
#include "JsonText.h"
#include "MemoryBudget.h"
#include "NumberList.h"
#include "OptionRange.h"
#include "OutputSet.h"
#include "cl/Device.h"
#include "compare/CompareReport.h"
#include "compare/Comparison.h"
#include "compare/EnvmapPdfComparison.h"
#include "compare/Suite.h"
#include "compare/Summary.h"
#include "compare/SummaryTables.h"
#include "paper/PaperReport.h"
#include "render/AlphaMap.h"
#include "render/BrdfCoverage.h"
#include "render/Costs.h"
#include "render/ImageMetrics.h"
#include "render/Method.h"
#include "render/Reference.h"
#include "render/Render.h"
#include "render/Report.h"
#include "render/Sampler.h"
#include "render/SamplerChoice.h"

using namespace misalloc;

namespace {

struct SceneArgs {
  SceneOptions options;
  std::string size = "128x128", view = "0", sampler = "alias", envmapPdf = "plain";

  void add(CLI::App* app) {
    app->add_option("--envmap", options.envmap,
                    "EXR path, shipped map name (forest_slope, rooitou_park, ...), constant[:R], cosk:K or "
                    "sun[:THETA,PHI,RADIUS,RATIO]")
        ->capture_default_str();
    app->add_option("--grid", options.grid, "seed000, general:RD0,RD1,N0,N1 or uniform:RD,RS,N")->capture_default_str();
    app->add_option("--size", size, "WxH pixels")->capture_default_str();
    app->add_option("--view", view, "view direction: polar angle THETA[,PHI] in degrees")->capture_default_str();
    app->add_flag("--split-brdf", options.splitBrdf,
                  "the BRDF's diffuse and specular lobes as separate techniques (M=3)");
    app->add_option("--envmap-sampler", sampler, "alias (O(1)) or cdf (two binary searches)")->capture_default_str();
    app->add_option("--procedural-width", options.proceduralWidth, "texel width of procedural envmaps")
        ->capture_default_str()
        ->check(integerIn(2, 16384));
  }

  // The options with --size, --view, --envmap-sampler and --envmap-pdf parsed; throws
  // InputError.
  SceneOptions parsed() {
    std::tie(options.width, options.height) = parseImageSize(size);
    const double pixels = double(options.width) * options.height;
    requireHostMemory(fmt::format("--size {} ({:g} pixels × {} B)", size, pixels, kRenderBytesPerPixel),
                      pixels * kRenderBytesPerPixel);
    std::vector<double> angles = parseNumberList("--view", view, view, 0, "expected THETA[,PHI] in degrees");
    if (angles.size() > 2) throw InputError(fmt::format("--view {}: expected THETA[,PHI] in degrees", view));
    options.viewTheta = angles[0];
    options.viewPhi = angles.size() > 1 ? angles[1] : 0;
    options.sampler = parseEnvmapSampler(sampler);
    options.envmapPdf = parseEnvmapPdf(envmapPdf);
    return options;
  }

  // [Kar19]: render only; a reference is equal MIS with the plain pdf, compare takes a list.
  void addEnvmapPdf(CLI::App* app) {
    app->add_option("--envmap-pdf", envmapPdf,
                    "plain (∝ luminance) or compensated[:C] (∝ max(0, L - 2(1-C) mean L), [Kar19] eq. 14; C "
                    "default 0.5)")
        ->capture_default_str();
  }

  Scene make() {
    parsed();
    Scene scene = makeScene(options);
    const ReadWarnings& repaired = scene.envmapWarnings;
    if (repaired.negativeValues > 0)
      std::cerr << fmt::format("misalloc: warning: {}: {} negative values set to 0 (first at {})\n", scene.envmapPath,
                               repaired.negativeValues, toString(repaired.firstNegative));
    if (scene.tables.uniformFallback)
      std::cerr << fmt::format("misalloc: warning: envmap '{}' is black: its sampling falls back to uniform\n",
                               options.envmap);
    if (scene.tables.requestedPdf.compensated() && !scene.tables.pdf.compensated())
      std::cerr << fmt::format(
          "misalloc: warning: envmap '{}': no texel exceeds 2(1-C) times the mean luminance; "
          "--envmap-pdf {} falls back to plain\n",
          options.envmap, envmapPdfName(scene.tables.requestedPdf));
    return scene;
  }
};

// The options of the adaptive methods, shared by render and compare.
struct AdaptiveArgs {
  AdaptiveOptions options;
  std::string costList, linearRule = "variance", gridRule = "variance";
  CLI::Option* costOption = nullptr;  // given, even as "", or not

  void add(CLI::App* app) {
    app->add_option("--pilot", options.pilotFraction, "adaptive methods: the pilot's share of the budget")
        ->capture_default_str()
        ->check(realIn(0, 1, true, true));
    app->add_option("--stages", options.stages, "adaptive methods: stages after the pilot")
        ->capture_default_str()
        ->check(integerIn(1, INT_MAX));
    app->add_option("--pool", options.poolRadius,
                    "adaptive methods: allocate from the statistics of the (2R+1)^2 pixels around each pixel")
        ->capture_default_str()
        ->check(integerIn(0, 1 << 12));
    app->add_option("--skip-below", options.minGain,
                    "exact: keep equal counts where the predicted gain of adapting is below this fraction")
        ->capture_default_str()
        ->check(realIn(0, 1, false, true));
    costOption = app->add_option("--cost", costList, "c1,c2[,c3]: cost per sample of each technique (default: measured)");
    app->add_option("--linear-rule", linearRule, "linear: negative weights by variance ([SS23] eq. 19) or drop")
        ->capture_default_str();
    // α is a float: beyond 2^24 combinations, neighbouring weights would coincide.
    app->add_option("--grid-u", options.gridSize, "exact, oracle: number U of weight combinations searched")
        ->capture_default_str()
        ->check(integerIn(2, 1 << 24));
    app->add_option("--grid-rule", gridRule,
                    "exact: select by minimum cost x variance (variance) or maximum entropy (entropy, [HS14] Alg. 1)")
        ->capture_default_str();
    app->add_option("--oracle-spp", options.oracleSamples, "oracle: probe samples per pixel")
        ->capture_default_str()
        ->check(integerIn(2, INT_MAX));
  }

  // The options with the rules parsed and the costs, when given, checked for M
  // techniques; throws InputError.
  AdaptiveOptions make(int techniqueCount) const;
};

GridRule parseGridRule(const std::string& name) {
  if (name == "variance") return GridRule::MinCostVariance;
  if (name == "entropy") return GridRule::MaxEntropy;
  throw InputError(fmt::format("--grid-rule '{}': expected variance or entropy", name));
}

ZeroWeightRule parseLinearRule(const std::string& name) {
  if (name == "variance") return ZeroWeightRule::MinSampleVariance;
  if (name == "drop") return ZeroWeightRule::DropMostNegative;
  throw InputError(fmt::format("--linear-rule '{}': expected variance ([SS23] eq. 19) or drop", name));
}

Estimator parseEstimator(const std::string& name) {
  if (name == "multi") return Estimator::MultiSample;
  if (name == "one") return Estimator::OneSample;
  throw InputError(fmt::format("--estimator '{}': expected multi or one", name));
}

AdaptiveOptions AdaptiveArgs::make(int techniqueCount) const {
  AdaptiveOptions o = options;
  o.linearRule = parseLinearRule(linearRule);
  o.gridRule = parseGridRule(gridRule);
  if (costOption->count() > 0) o.costs = parseCosts(costList, techniqueCount);
  return o;
}

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

// The envmap files that the scenes read: no output may replace one.
std::vector<NamedFile> envmapInputs(const std::vector<SceneOptions>& scenes) {
  std::vector<NamedFile> inputs;
  for (const SceneOptions& o : scenes) {
    std::string file = resolveEnvmapSpec(o.envmap);
    if (std::filesystem::exists(file)) inputs.push_back({"--envmap", file});
  }
  return inputs;
}

// The host memory of the samples a method stores and, on the C++ device, of the grid
// search's sums, refused up front with the option that asks for it: `sppOption` is
// --spp for render, --budgets for compare.
void requireStatisticsMemory(const SceneOptions& scene, Method m, const std::string& sppOption, int spp,
                             const AdaptiveOptions& adaptive, bool onHost) {
  const SamplerConfig config = samplerConfigFor(m, Estimator::MultiSample, spp, adaptive);
  const double pixels = double(scene.width) * scene.height, M = scene.splitBrdf ? 3 : 2;
  if (config.sampleCapacity > 0) {
    // A record of M + 2 floats per sample, on a CPU device once in its buffer and once
    // read back (kernels/stats.h).
    const double perPixel = double(config.sampleCapacity) * (M + 2) * sizeof(float) * 2;
    std::string option = fmt::format("{} {}", sppOption, spp);
    if (m == Method::Oracle) option += fmt::format(" and --oracle-spp {}", adaptive.oracleSamples);
    requireHostMemory(fmt::format("{} with --method {} ({:g} pixels × {} stored samples × {:g} B)", option,
                                  methodName(m), pixels, config.sampleCapacity, (M + 2) * sizeof(float) * 2),
                      pixels * perPixel);
  }
  if (config.gridSize > 0) {
    // The weight grid, M weights and a cost per combination, is built on the host; the
    // running sums, Σ g and Σ g² per technique and combination, too on the C++ device
    // (alloc/GridSearch.h). Both from the options alone: building the grid to size it
    // would be the allocation this check prevents.
    const double U = config.gridSize, gridBytes = U * (M + 1) * sizeof(float);
    const double sumBytes = onHost ? pixels * 2 * M * U * sizeof(float) : 0;
    requireHostMemory(fmt::format("--grid-u {} ({:g} combinations × {:g} B{})", config.gridSize, U,
                                  (M + 1) * sizeof(float),
                                  sumBytes > 0 ? fmt::format(", and {:g} pixels × {:g} B of sums", pixels,
                                                             2 * M * U * sizeof(float))
                                               : ""),
                      gridBytes + sumBytes);
  }
}

// CLI11 takes a word it does not know for a stray argument; say what it is instead.
void refuseUnknownSubcommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return;
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  if (std::find(names.begin(), names.end(), argv[1]) == names.end())
    throw InputError(fmt::format("unknown subcommand '{}'; the subcommands are {}", argv[1], fmt::join(names, ", ")));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"misalloc: per-pixel allocation of MIS samples for envmap x BRDF direct lighting"};
  app.require_subcommand(1);
  // A repeated option takes its last value, as in most command-line tools.
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);

  app.add_subcommand("devices", "list OpenCL platforms and devices");

  auto* renderCmd = app.add_subcommand("render", "render a scene (default: forest_slope x seed000, 128x128, 200 spp)");
  SceneArgs renderScene;
  renderScene.add(renderCmd);
  renderScene.addEnvmapPdf(renderCmd);
  int spp = 200, localSize = 8, referenceSpp = 16384;
  uint64_t seed = 1;
  std::string method = "exact", estimatorName = "multi", deviceSpec = "auto", out = "render.exr",
              reportPath = "render.json", referenceMode = "auto", cacheDir = defaultCacheDir();
  renderCmd->add_option("--spp", spp, "samples per pixel")->capture_default_str()->check(integerIn(1, INT_MAX));
  renderCmd->add_option("--method", method, "envmap, brdf, equal, heuristic, sigma-sqrt-c, linear or exact")
      ->capture_default_str();
  AdaptiveArgs renderAdaptive;
  renderAdaptive.add(renderCmd);
  std::string alphaMap;
  renderCmd->add_option("--alpha-map", alphaMap, "write the per-pixel allocation: EXR here, false-colour PNG beside");
  renderCmd->add_option("--estimator", estimatorName, "fixed splits: multi ([HS14] eq. 4.1) or one (one-sample MIS)")
      ->capture_default_str();
  renderCmd->add_option("--seed", seed, "random seed")->capture_default_str()->check(anyUnsigned64());
  renderCmd->add_option("--device", deviceSpec, "comma-separated: auto, cpu, gpu, an index from `misalloc devices`, host (C++), all, or D:N (device D in N sub-devices)")
      ->capture_default_str();
  renderCmd->add_option("--out", out, "output EXR")->capture_default_str();
  renderCmd->add_option("--report", reportPath, "output JSON report")->capture_default_str();
  renderCmd
      ->add_option("--reference", referenceMode,
                   "auto (analytic, cached, or computed and cached), none, or an EXR path")
      ->capture_default_str();
  renderCmd->add_option("--reference-spp", referenceSpp, "spp of a sampled reference")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  renderCmd->add_option("--cache-dir", cacheDir, "where references are cached")->capture_default_str();
  renderCmd->add_option("--local-size", localSize, "OpenCL work-group size")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));

  auto* referenceCmd = app.add_subcommand("reference", "compute (or find in the cache) a converged reference image");
  SceneArgs referenceScene;
  referenceScene.add(referenceCmd);
  std::string referenceOut;
  referenceCmd->add_option("--spp", referenceSpp, "samples per pixel")->capture_default_str()->check(integerIn(1, INT_MAX));
  referenceCmd->add_option("--device", deviceSpec, "comma-separated: auto, cpu, gpu, index, host, all or D:N")->capture_default_str();
  referenceCmd->add_option("--cache-dir", cacheDir, "where references are cached")->capture_default_str();
  referenceCmd->add_option("--out", referenceOut, "also write the reference to this EXR");

  auto* compareCmd = app.add_subcommand(
      "compare", "error against time: methods x budgets x repeats, equal-time tables, plots and index.html");
  SceneArgs compareScene;
  compareScene.add(compareCmd);
  AdaptiveArgs compareAdaptive;
  compareAdaptive.add(compareCmd);
  CompareOptions compare;
  std::string methodList = "all", budgetList = "50,100,200,400,800", envmapPdfList = "plain";
  bool suite = false;
  compareCmd->add_flag("--suite", suite,
                       "every shipped envmap x seed000 plus forest_slope with the cdf sampler, at 64x64 unless --size");
  compareCmd->add_option("--methods", methodList, "comma-separated methods, or all")->capture_default_str();
  compareCmd->add_option("--budgets", budgetList, "samples per pixel, ascending")->capture_default_str();
  compareCmd
      ->add_option("--envmap-pdfs", envmapPdfList, "envmap pdfs, each scene runs with each: plain, compensated[:C]")
      ->capture_default_str();
  compareCmd->add_option("--repeats", compare.repeats, "independent seeds per method and budget")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  compareCmd->add_option("--seed", compare.seed, "repeat r uses seed + r")->capture_default_str()->check(anyUnsigned64());
  compareCmd->add_option("--table-spp", compare.tableBudget, "the budget of the Table 5.2 layout (nearest one run)")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  compareCmd->add_option("--out-dir", compare.outDir, "output folder (created if missing)")->required();
  compareCmd->add_option("--device", compare.device, "comma-separated: auto, cpu, gpu, an index, host (C++), all or D:N")->capture_default_str();
  compareCmd->add_option("--local-size", compare.localSize, "OpenCL work-group size")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  compareCmd->add_option("--reference-spp", compare.referenceSpp, "spp of a sampled reference")
      ->capture_default_str()
      ->check(integerIn(1, INT_MAX));
  compare.cacheDir = defaultCacheDir();
  compareCmd->add_option("--cache-dir", compare.cacheDir, "where references are cached")->capture_default_str();

  auto* paperCmd = app.add_subcommand("paper", "the papers' 1D examples: list them, or print one against the papers");
  std::string paperId;
  paperCmd->add_option("id", paperId, "example id (see `misalloc paper`)");

  try {
    refuseUnknownSubcommand(app, argc, argv);
    app.parse(argc, argv);
    if (app.got_subcommand("devices")) {
      listDevices(std::cout);
    } else if (app.got_subcommand("paper")) {
      if (paperId.empty()) {
        listPaperExamples(std::cout);
      } else {
        const std::vector<std::string> ids = paperExampleIds();
        if (std::find(ids.begin(), ids.end(), paperId) == ids.end())
          throw InputError(fmt::format("paper {}: unknown example; valid ids: {}", paperId, fmt::join(ids, ", ")));
        printPaperExample(paperId, std::cout);
      }
    } else if (app.got_subcommand("render")) {
      Method m = parseMethod(method);
      Estimator estimator = parseEstimator(estimatorName);
      if (isAdaptive(m) && estimator != Estimator::MultiSample)
        throw InputError(fmt::format("--estimator {}: the adaptive methods take multi-sample stages", estimatorName));
      std::vector<NamedFile> inputs = envmapInputs({renderScene.parsed()});
      if (referenceMode != "auto" && referenceMode != "none") inputs.push_back({"--reference", referenceMode});
      OutputSet outputs(inputs);
      outputs.claim("--out", out);
      outputs.claim("--report", reportPath);
      if (!alphaMap.empty()) {
        outputs.claim("--alpha-map", alphaMap);
        outputs.claim("--alpha-map", alphaPngPath(alphaMap));
      }
      Scene scene = renderScene.make();
      AdaptiveOptions adaptive = renderAdaptive.make(scene.techniqueCount());
      requireBrdfCoverage(scene.options.envmapPdf, scene.techniqueCount(), m, estimator, spp, adaptive);
      std::string costSource = adaptive.costs.empty() ? "measured" : "--cost";
      if (isAdaptive(m) && m != Method::Oracle)
        stageSizes(adaptive.pilotFraction, adaptive.stages, spp, scene.techniqueCount());
      if (m == Method::Oracle && adaptive.oracleSamples < 2 * scene.techniqueCount())
        throw InputError(
            fmt::format("--oracle-spp {}: the probe needs at least 2 samples per technique", adaptive.oracleSamples));
      SamplerDevices devices(deviceSpec);
      SamplerConfig config = samplerConfigFor(m, estimator, spp, adaptive);
      requireStatisticsMemory(scene.options, m, "--spp", spp, adaptive, devices.includesHost());
      auto sampler = devices.makeSampler(scene, config, localSize);
      std::string deviceName = devices.name();
      // Without statistics: for the reference and for measuring costs.
      std::unique_ptr<StageSampler> plain;
      const Scene plainScene = withPlainEnvmapPdf(scene);  // [Kar19]: the reference's pdf is plain
      auto plainSampler = [&]() -> StageSampler& {
        if (!plain) plain = devices.makeSampler(plainScene, SamplerConfig{}, localSize);
        return *plain;
      };
      std::optional<Reference> reference;
      if (referenceMode == "auto")
        reference = findReference(plainSampler(), plainScene, referenceSpp, cacheDir, true);
      else if (referenceMode != "none")
        reference = Reference{readExr(referenceMode), "file", referenceMode};
      if (reference) checkSameSize(RgbImage{scene.grid.width, scene.grid.height, {}}, reference->image);
      if (isAdaptive(m) && adaptive.costs.empty()) adaptive.costs = measureCosts(plainSampler());
      Rendering r = render(*sampler, m, adaptive, spp, seed);
      nlohmann::json report =
          renderReport({scene, m, config.estimator, adaptive, costSource, spp, seed, deviceName, r, reference});
      outputs.put(out, encodeExr(r.image));
      if (!alphaMap.empty()) {
        AlphaMapFiles alpha = encodeAlphaMaps(scene, r);
        outputs.put(alphaMap, std::move(alpha.exr));
        outputs.put(alphaPngPath(alphaMap), std::move(alpha.png));
      }
      outputs.put(reportPath, jsonText(report));
      outputs.commit();
      std::cout << fmt::format("{} | {} x {} | {}x{} | {} spp | {} | {:.3f} s (kernel {:.3f} s, allocation {:.3f} s)\n",
                               deviceName, scene.options.envmap, scene.options.grid, scene.grid.width,
                               scene.grid.height, spp, methodName(m), r.wallSeconds, r.kernelSeconds,
                               r.allocationSeconds);
      if (reference)
        std::cout << fmt::format("RMSE x1000 {:.3f}, relative MSE {:.4g} (reference: {})\n",
                                 report["rmse_x1000"].get<double>(), report["relative_mse"].get<double>(),
                                 reference->source);
      std::cout << fmt::format("wrote {} and {}{}\n", out, reportPath,
                               alphaMap.empty() ? "" : fmt::format(", {} and {}", alphaMap, alphaPngPath(alphaMap)));
    } else if (app.got_subcommand("compare")) {
      InterruptionGuard guard;  // first: every thread started from here on inherits its mask
      if (suite) {
        for (const char* sceneOption : {"--envmap", "--grid", "--envmap-sampler", "--split-brdf"})
          if (compareCmd->count(sceneOption) > 0)
            throw InputError(fmt::format("--suite runs its own scenes: drop {}", sceneOption));
        if (compareCmd->count("--size") == 0) compareScene.size = "64x64";
        Scene probe = compareScene.make();  // checks --size and --view
        for (CompareCase c : suiteCases(probe.grid.width, probe.grid.height)) {
          c.scene.viewTheta = probe.options.viewTheta;
          c.scene.viewPhi = probe.options.viewPhi;
          compare.cases.push_back(c);
        }
      } else {
        Scene probe = compareScene.make();  // reads the envmap once, so bad input fails before any work
        compare.cases.push_back({caseLabel(probe.options), probe.options});
      }
      compare.cases = casesPerEnvmapPdf(compare.cases, parseEnvmapPdfList(envmapPdfList));
      compare.methods = parseMethodList(methodList);
      compare.budgets = parseBudgets(budgetList);
      compare.adaptive = compareAdaptive.make(compare.cases.front().scene.splitBrdf ? 3 : 2);
      validateCompareOptions(compare);
      for (const CompareCase& c : compare.cases)
        for (Method m : compare.methods)
          for (int budget : compare.budgets)
            requireStatisticsMemory(c.scene, m, "--budgets", budget, compare.adaptive,
                                    SamplerDevices(compare.device).includesHost());
      requireBrdfCoverage(compare);
      std::vector<SceneOptions> scenes;
      for (const CompareCase& c : compare.cases) scenes.push_back(c.scene);
      OutputSet outputs(envmapInputs(scenes));
      const std::string outDir = compare.outDir;
      compare.outDir = outputs.claimFolder("--out-dir", outDir);  // filled as it runs, moved in at the end
      Comparison comparison = runComparison(compare, guard);
      Summary summary = summarize(comparison, compare);
      writeCompareReport(summary, compare.outDir);
      const std::string envmapPdfTables = envmapPdfMarkdown(summary);
      if (!envmapPdfTables.empty()) writeFileAtomically(compare.outDir + "/envmap_pdfs.md", envmapPdfTables);
      outputs.commit();
      if (comparison.interrupted) {
        std::cerr << fmt::format("misalloc: interrupted after {} runs; {} holds them, every file complete\n",
                                 comparison.runs.size(), outDir);
        return 130;
      }
      std::cout << summaryMarkdown(summary) << envmapPdfTables;
      std::cout << fmt::format("\nwrote {}/index.html, summary.{{md,csv,json}}, budgets.csv, runs.{{json,csv}}\n",
                               outDir);
    } else if (app.got_subcommand("reference")) {
      OutputSet outputs(envmapInputs({referenceScene.parsed()}));
      if (!referenceOut.empty()) outputs.claim("--out", referenceOut);
      Scene scene = referenceScene.make();
      auto sampler = SamplerDevices(deviceSpec).makeSampler(scene, SamplerConfig{}, localSize);
      auto reference = findReference(*sampler, scene, referenceSpp, cacheDir, true);
      if (!referenceOut.empty()) outputs.put(referenceOut, encodeExr(reference->image));
      outputs.commit();
      std::cout << fmt::format("reference: {}{}\n", reference->source,
                               reference->path.empty() ? "" : " at " + reference->path);
    }
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "misalloc: error: " << e.what() << "\nRun with --help for more information.\n";
    return 2;  // CLI11's own codes (104–114) would each mean "bad input" too
  } catch (const InputError& e) {
    std::cerr << "misalloc: error: " << e.what() << "\n";
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "misalloc: error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "misalloc: error: out of memory: --size, --spp and --grid-u of the adaptive methods, and the "
                 "envmap's texels decide how much a run needs\n";
    return 2;
  } catch (const DeviceError& e) {
    std::cerr << "misalloc: OpenCL error: " << e.what() << "\n";
    return 3;
  } catch (const cl::Error& e) {
    std::cerr << "misalloc: OpenCL error: " << e.what() << " (code " << e.err() << ")\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "misalloc: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
