#include "compare/Comparison.h"

#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <memory>

#include "AtomicFile.h"
#include "Error.h"
#include "JsonText.h"
#include "compare/ProgressMeter.h"
#include "render/BandFile.h"
#include "render/CostCache.h"
#include "render/Reference.h"
#include "render/RunChecks.h"
#include "report/AlphaMap.h"
#include "report/ImageMetrics.h"
#include "report/PreviewPng.h"
#include "report/Report.h"
#include "report/RunSummary.h"
#include "sampling/SamplerChoice.h"

namespace misalloc {
namespace fs = std::filesystem;
namespace {

// Where a case's adaptive renders take their costs (each run's costs_source says which
// of the cache or a calibration it was).
std::string costPolicy(const AdaptiveOptions& adaptive) {
  if (!adaptive.costs.empty()) return "--cost";
  return adaptive.measureCosts ? "calibrated (--cost measure), then cached" : "the cost cache";
}

std::string runStem(const std::string& caseLabel, Method method, int budget) {
  return fmt::format("{}/{}_{}spp", caseLabel, methodName(method), budget);
}

RunRecord recordRun(const CaseInfo& info, Method method, int budget, int repeat, uint64_t seed, const Rendering& r,
                    const Reference& reference) {
  RunRecord rec;
  rec.caseLabel = info.label;
  rec.method = method;
  rec.budget = budget;
  rec.repeat = repeat;
  rec.seed = seed;
  rec.node = nodeName();
  rec.wallSeconds = r.wallSeconds;
  rec.kernelSeconds = r.kernelSeconds;
  rec.allocationSeconds = r.allocationSeconds;
  rec.hostSeconds = r.hostSeconds;
  RunSummary s = summarizeRun(r, int(info.techniques.size()), &reference);
  rec.mse = s.corrected->mse;
  rec.mseStandardError = s.corrected->standardError;
  rec.rawMse = *s.mse;
  rec.relativeMse = *s.relativeMse;
  rec.meanAlpha = std::move(s.meanAlpha);
  rec.fallbackFraction = s.fallbackFraction;
  rec.flooredFraction = s.flooredFraction;
  rec.skippedFraction = s.skippedFraction;
  rec.weightsFallbackFraction = s.weightsFallbackFraction;
  rec.statisticsBytesPerPixel = r.statisticsBytesPerPixel;
  rec.predictedGain = r.predictedGain;
  rec.keptEqualCounts = r.keptEqualCounts;
  rec.stages = r.stages;
  if (r.costModel) rec.costSource = costSourceName(r.costModel->source());
  return rec;
}

nlohmann::json runJson(const RunRecord& r) {
  return {{"case", r.caseLabel},
          {"method", methodName(r.method)},
          {"spp", r.budget},
          {"repeat", r.repeat},
          {"seed", r.seed},
          {"node", r.node},
          {"time_s", timeSplitJson(r.wallSeconds, r.kernelSeconds, r.allocationSeconds, r.hostSeconds)},
          {"rmse_x1000", 1000 * std::sqrt(r.rawMse)},
          {"rmse_x1000_corrected", 1000 * std::sqrt(std::max(0.0, r.mse))},
          {"mse_corrected", r.mse},
          {"mse_corrected_standard_error", r.mseStandardError},
          {"relative_mse", r.relativeMse},
          {"efficiency", r.efficiency()},
          {"mean_alpha", r.meanAlpha},
          {"fallback_pixel_fraction", r.fallbackFraction},
          {"floored_pixel_fraction", r.flooredFraction},
          {"skipped_pixel_fraction", r.skippedFraction},
          {"weights_fallback_pixel_fraction", r.weightsFallbackFraction},
          {"statistics_bytes_per_pixel", r.statisticsBytesPerPixel},
          {"costs_source", r.costSource},
          {"predicted_gain", optionalJson(r.predictedGain)},
          {"kept_equal_counts", r.keptEqualCounts},
          {"stages", stagesJson(r.stages)}};
}

nlohmann::json leftOutJson(const std::vector<LeftOutMethod>& leftOut) {
  nlohmann::json list = nlohmann::json::array();
  for (const LeftOutMethod& l : leftOut) list.push_back({{"method", methodName(l.method)}, {"why", l.why}});
  return list;
}

std::string runsCsv(const Comparison& comparison) {
  std::string csv =
      "case,method,spp,repeat,seed,wall_s,kernel_s,allocation_s,host_s,rmse_x1000,mse_corrected,"
      "mse_corrected_standard_error,relative_mse,efficiency,"
      "mean_alpha_envmap,fallback_pixel_fraction,floored_pixel_fraction,skipped_pixel_fraction,"
      "weights_fallback_pixel_fraction,statistics_bytes_per_pixel,predicted_gain,kept_equal_counts\n";
  for (const RunRecord& r : comparison.runs)
    csv += fmt::format(
        "{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},"
        "{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{},{},{}\n",
        r.caseLabel, methodName(r.method), r.budget, r.repeat, r.seed, r.wallSeconds, r.kernelSeconds,
        r.allocationSeconds, r.hostSeconds, 1000 * std::sqrt(r.rawMse), r.mse, r.mseStandardError, r.relativeMse,
        r.efficiency(), r.meanAlpha.front(), r.fallbackFraction, r.flooredFraction, r.skippedFraction,
        r.weightsFallbackFraction, r.statisticsBytesPerPixel,
        r.predictedGain ? fmt::format("{:.6g}", *r.predictedGain) : std::string(), r.keptEqualCounts ? 1 : 0);
  return csv;
}

}  // namespace

nlohmann::json caseInfoJson(const CaseInfo& c) {
  return {{"label", c.label},
          {"scene", c.scene},
          {"techniques", c.techniques},
          {"costs_s_per_sample", c.costs},
          {"costs_source", c.costSource},
          {"reference", c.referenceSource},
          {"reference_variance", c.referenceVariance},
          {"device", c.device},
          {"left_out", leftOutJson(c.leftOut)},
          {"repeats", c.repeats},
          {"weights", misWeightsName(c.weights)}};
}

// Rewritten after every run, so that an interrupted comparison keeps what finished.
void writeRuns(const std::string& outDir, const Comparison& comparison) {
  nlohmann::json json = {
      {"interrupted", comparison.interrupted}, {"cases", nlohmann::json::array()}, {"runs", nlohmann::json::array()}};
  for (const CaseInfo& c : comparison.cases) json["cases"].push_back(caseInfoJson(c));
  for (const RunRecord& r : comparison.runs) json["runs"].push_back(runJson(r));
  writeFileAtomically(outDir + "/runs.json", jsonText(json));
  writeFileAtomically(outDir + "/runs.csv", runsCsv(comparison));
}

std::string imagePath(const std::string& caseLabel, Method method, int budget) {
  return runStem(caseLabel, method, budget) + ".exr";
}

std::string alphaMapPath(const std::string& caseLabel, Method method, int budget) {
  return runStem(caseLabel, method, budget) + "_alpha.exr";
}

std::vector<Method> caseMethods(const CompareCase& c, const std::vector<Method>& methods) {
  std::vector<Method> out;
  for (Method m : methods)
    if (std::none_of(c.leftOut.begin(), c.leftOut.end(), [&](const LeftOutMethod& l) { return l.method == m; }))
      out.push_back(m);
  return out;
}

void validateCompareOptions(const CompareOptions& options) {
  if (options.cases.empty()) throw InputError("compare: no scene");
  if (options.methods.empty()) throw InputError("--methods: no method");
  if (options.budgets.empty()) throw InputError("--budgets: no budget");
  for (size_t i = 0; i < options.budgets.size(); ++i) {
    if (options.budgets[i] < 1)
      throw InputError(fmt::format("--budgets: {} is not a positive spp", options.budgets[i]));
    if (i > 0 && options.budgets[i] <= options.budgets[i - 1])
      throw InputError("--budgets: list each budget once, in ascending order");
  }
  if (options.repeats < 1) throw InputError(fmt::format("--repeats {}: need at least 1", options.repeats));
  for (const CompareCase& c : options.cases) {
    AdaptiveOptions adaptive = options.adaptive;
    adaptive.weights = c.weights;
    for (Method m : caseMethods(c, options.methods))
      for (int budget : options.budgets) requireValidRun(c.scene, m, Estimator::MultiSample, budget, adaptive);
  }
}

Comparison runComparison(const CompareOptions& options, InterruptionGuard& guard) {
  fs::create_directories(options.outDir);
  int runs = 0;
  for (const CompareCase& c : options.cases)
    runs += int(caseMethods(c, options.methods).size() * options.budgets.size() * c.repeats.size());
  ProgressMeter meter(runs);
  SamplerDevices devices(options.device);
  Comparison out;
  for (const CompareCase& c : options.cases) {
    const std::vector<Method> methods = caseMethods(c, options.methods);
    Scene scene = makeScene(c.scene);
    fs::create_directories(fs::path(options.outDir) / c.label);
    // The reference of the plain envmap pdf's scene ([Kar19]: withPlainEnvmapPdf).
    const Scene plainScene = withPlainEnvmapPdf(scene);
    meter.note(fmt::format("{}: reference ({} spp, computed once and cached)", c.label, options.referenceSpp));
    const Reference reference = findReference(plainScene, options.referenceSpp, options.cacheDir, [&](const Scene& s) {
      return devices.makeSampler(s, SamplerConfig{}, options.localSize);
    });
    AdaptiveOptions adaptive = options.adaptive;
    adaptive.weights = c.weights;
    double referenceVariance = 0;
    for (float e : reference.standardError) referenceVariance += double(e) * e / double(reference.image.rgb.size());
    out.cases.push_back({c.label, sceneJson(scene), scene.techniqueNames(), adaptive.costs, costPolicy(adaptive),
                         reference.source, referenceVariance, devices.name(), c.leftOut, c.repeats, c.weights});
    const CaseInfo& info = out.cases.back();
    const double exposure = previewExposure(reference.image);
    writePreviewPng(fmt::format("{}/{}/reference.png", options.outDir, c.label), reference.image, exposure);
    // The repeats go round the methods, so that a stretch of load from elsewhere on a
    // shared machine slows one repeat of every method rather than every repeat of one:
    // the median times then compare methods under the same conditions.
    for (int budget : options.budgets) {
      // Built (and their kernels compiled) once per budget; each render starts afresh.
      std::vector<std::unique_ptr<StageSampler>> samplers;
      for (Method method : methods) {
        samplers.push_back(devices.makeSampler(
            scene, samplerConfigFor(method, Estimator::MultiSample, budget, adaptive, scene.techniqueCount()),
            options.localSize));
        if (isAdaptive(method) && adaptive.costs.empty())
          provideCostModel(*samplers.back(), plainScene, {options.cacheDir, adaptive.measureCosts});
      }
      for (int r : c.repeats)
        for (size_t m = 0; m < methods.size(); ++m) {
          const Method method = methods[m];
          if (guard.requested()) {
            out.interrupted = true;
            writeRuns(options.outDir, out);
            return out;
          }
          const uint64_t seed = options.seed + uint64_t(r);
          Rendering rendering = render(*samplers[m], method, adaptive, budget, seed);
          out.runs.push_back(recordRun(info, method, budget, r, seed, rendering, reference));
          if (r == 0) {
            std::string image = options.outDir + "/" + imagePath(c.label, method, budget);
            writeExr(image, rendering.image);
            writePreviewPng(previewPath(image), rendering.image, exposure);
            if (isAdaptive(method))
              writeAlphaMaps(options.outDir + "/" + alphaMapPath(c.label, method, budget), scene, rendering);
          }
          writeRuns(options.outDir, out);
          meter.step(fmt::format("{} {} {} spp #{}", c.label, methodName(method), budget, r + 1));
        }
    }
    cacheOptimalBank(scene);
  }
  return out;
}

}  // namespace misalloc
