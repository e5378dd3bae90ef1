#include "report/Report.h"

#include <algorithm>
#include <cmath>

#include "JsonText.h"
#include "KernelCode.h"
#include "report/RunSummary.h"

namespace misalloc {

std::string estimatorName(Estimator estimator) {
  switch (estimator) {
    case Estimator::MultiSample:
      return "multi-sample balance heuristic";
    case Estimator::OneSample:
      return "one-sample balance heuristic";
    case Estimator::CountIndependent:
      return "count-independent weights ([SHS16] eq. 26)";
    case Estimator::Resampled:
      return "resampled importance sampling of envmap candidates ([TCE05])";
  }
  return "?";
}

namespace {

nlohmann::json pixelCellsJson(const EnvmapTables& tables) {
  return {{"cells", tables.pixelCells},
          {"across", (tables.width + (1 << tables.blockLog2) - 1) >> tables.blockLog2},
          {"cell_texels", 1 << (2 * tables.blockLog2)},
          {"table_bytes", (tables.aliasTable.size() + tables.blockProbs.size()) * 4},
          {"build_seconds", tables.bankBuildSeconds}};
}

// [Kar19]: the pdf asked for and the one sampled with; a compensated pdf that left no
// texel positive fell back to plain.
nlohmann::json envmapPdfJson(const EnvmapTables& tables) {
  nlohmann::json pdf = {{"requested", envmapPdfName(tables.requestedPdf)},
                        {"used", envmapPdfName(tables.pdf)},
                        {"mean_luminance", tables.meanLuminance}};
  if (tables.requestedPdf.compensated()) {
    pdf["fallback_to_plain"] = !tables.pdf.compensated();
    if (!tables.pdf.compensated())
      pdf["fallback_reason"] = "no texel's luminance exceeds 2(1-C) times the mean (a constant map?)";
    pdf["zero_texel_fraction"] = tables.zeroTexelFraction;
  }
  if (tables.requestedPdf.optimal() || tables.requestedPdf.pixelOptimal()) {
    pdf["fallback_to_plain"] = !tables.followsEnvmapShare();
    if (!tables.followsEnvmapShare()) pdf["fallback_reason"] = "the map is black";
  }
  if (tables.pixelCells > 0) pdf["pixel_cells"] = pixelCellsJson(tables);
  if (tables.hasBank()) {
    const BankVariances& v = tables.bankVariances;
    const std::size_t entries = std::size_t(tables.brdfBins) * tables.bankShares;
    pdf["bank"] = {{"brdf_bins", tables.brdfBins},
                   {"envmap_shares", tables.bankShares},
                   {"entries", entries},
                   {"block_texels", 1 << (2 * tables.blockLog2)},
                   // The sampling tables beside the texels: a plain alias table holds 8 B per texel.
                   {"table_bytes", (tables.aliasTable.size() + tables.cdfTable.size() + tables.blockProbs.size()) * 4},
                   {"build_seconds", tables.bankBuildSeconds},
                   {"from_cache", tables.bankFromCache},
                   {"one_sample_variance_eq6_over_eq9_max", v.compensatedOverOptimalMax},
                   {"one_sample_variance_eq6_over_eq9_mean", v.compensatedOverOptimalMean},
                   {"entries_with_negative_eq5", v.entriesWithNegativeEq5}};
  }
  return pdf;
}

// Each device's share of the pixels and samples; with several, how far apart they
// finished (sampling/TiledSampler.h).
nlohmann::json devicesJson(const Rendering& r) {
  long long pixelStages = 0, samples = 0;
  for (const DeviceShare& d : r.devices) pixelStages += d.pixelStages, samples += d.samples;
  nlohmann::json list = nlohmann::json::array();
  for (const DeviceShare& d : r.devices) {
    nlohmann::json entry = {{"name", d.name},
                            {"launch", d.launch},
                            {"pixel_share", pixelStages > 0 ? double(d.pixelStages) / pixelStages : 0.0},
                            {"sample_share", samples > 0 ? double(d.samples) / samples : 0.0},
                            {"samples", d.samples},
                            {"tiles", d.tiles},
                            {"kernel_s", d.kernelSeconds}};
    if (!d.failure.empty()) entry["failed"] = d.failure + "; its tiles ran again on the other devices";
    list.push_back(entry);
  }
  return list;
}

// The weights of the multi-sample stages; with [Kon19]'s optimal weights, the pixels
// whose stages kept the balance heuristic, and why (alloc/OptimalWeights.h).
nlohmann::json weightsJson(MisWeights weights, const Rendering& r, const RunSummary& summary) {
  nlohmann::json json = {{"rule", misWeightsName(weights)}};
  if (weights != MisWeights::Optimal) return json;
  const OptimalWeightsFallbacks& f = r.weightsFallbacks;
  json["fallback_pixels"] = f.pixels;
  json["fallback_pixel_fraction"] = summary.weightsFallbackFraction;
  json["fallback_reasons"] = {{"too_few_samples", f.tooFewSamples},
                              {"ill_conditioned", f.illConditioned},
                              {"non_finite", f.nonFinite},
                              {"other_envmap_table", f.otherEnvmapTable}};
  return json;
}

}  // namespace

nlohmann::json sceneJson(const Scene& scene) {
  const SceneOptions& o = scene.options;
  nlohmann::json json = {{"envmap", o.envmap},
                         {"envmap_file", scene.envmapPath},
                         {"envmap_size", {scene.tables.width, scene.tables.height}},
                         {"envmap_uniform_fallback", scene.tables.uniformFallback},
                         {"envmap_negative_values_zeroed", scene.envmapWarnings.negativeValues},
                         {"grid", scene.grid.spec},
                         {"shape", o.shape},
                         {"size", {o.width, o.height}},
                         {"covered_pixels", scene.geometry.coveredPixels()},
                         {"view_deg", {o.viewTheta, o.viewPhi}},
                         {"techniques", scene.techniqueNames()},
                         {"envmap_sampler", scene.tables.useCdf ? "cdf" : "alias"},
                         {"envmap_pdf", envmapPdfJson(scene.tables)}};
  if (scene.pilotTables.pixelCells > 0) json["envmap_pdf"]["pilot_cells"] = pixelCellsJson(scene.pilotTables);
  if (scene.productTables.pixelCells)
    json["product"] = {{"from", "pixel_cells"}, {"plain_share", MA_PIXEL_PLAIN_SHARE}, {"table_bytes", 0}};
  else if (scene.productTables.enabled())
    json["product"] = {{"from", "tables"},
                       {"tables", scene.productTables.tables},
                       {"specular_tables", scene.productTables.tables - MA_PRODUCT_TABLE_DIFFUSE - 1},
                       {"block_texels", 1 << (2 * scene.productTables.blockLog2)},
                       {"plain_share", MA_PRODUCT_PLAIN_SHARE},
                       {"table_bytes", scene.productTables.bytes()},
                       {"build_seconds", scene.productTables.buildSeconds}};
  return json;
}

nlohmann::json timeSplitJson(double wall, double kernel, double allocation, double host) {
  return {{"wall", wall}, {"kernel", kernel}, {"allocation", allocation}, {"host", host}};
}

nlohmann::json stagesJson(const std::vector<StageTiming>& stages) {
  nlohmann::json list = nlohmann::json::array();
  for (const StageTiming& s : stages) {
    nlohmann::json entry = {
        {"samples", s.samples}, {"keeps_statistics", s.keptStatistics}, {"kernel_s", s.kernelSeconds}};
    if (s.predictedKernelSeconds) {
      entry["predicted_kernel_s"] = *s.predictedKernelSeconds;
      entry["predicted_over_measured"] = *s.predictedKernelSeconds / s.kernelSeconds;
    }
    list.push_back(entry);
  }
  return list;
}

nlohmann::json costModelJson(const CostModel& model, const std::vector<std::string>& techniqueNames) {
  nlohmann::json kernels;
  for (bool statistics : {false, true}) {
    nlohmann::json perSample;
    for (size_t k = 0; k < techniqueNames.size(); ++k) perSample[techniqueNames[k]] = model.perSample(statistics)[k];
    kernels[statistics ? "with_statistics" : "plain"] = {{"per_launch_s", model.perLaunch(statistics)},
                                                         {"per_sample_s", perSample},
                                                         {"launches_fitted", model.launchCount(statistics)}};
  }
  return {{"source", costSourceName(model.source())},
          {"model", "T = t_0 + sum_k c_k S_k, S_k: technique k's sample slots as the work-groups run them"},
          {"kernels", kernels}};
}

nlohmann::json renderReport(const RenderRun& run) {
  const Rendering& r = run.rendering;
  // Over the covered pixels: the background's variance is 0, its samples none.
  const double pixels = double(r.image.coveredPixels());
  const int M = run.scene.techniqueCount();
  double meanVariance = 0;
  for (double v : r.variance) meanVariance += v;
  meanVariance /= pixels;
  const RunSummary summary = summarizeRun(r, M, run.reference ? &*run.reference : nullptr);
  nlohmann::json meanAlpha;
  auto names = run.scene.techniqueNames();
  for (int k = 0; k < M; ++k) meanAlpha[names[k]] = summary.meanAlpha[k];
  nlohmann::json report = {
      {"scene", sceneJson(run.scene)},
      {"method", methodName(run.method)},
      {"estimator", estimatorName(run.estimator)},
      {"weights", weightsJson(run.adaptive.weights, r, summary)},
      {"spp", run.spp},
      {"seed", run.seed},
      {"device", run.device},
      {"time_s", timeSplitJson(r.wallSeconds, r.kernelSeconds, r.allocationSeconds, r.hostSeconds)},
      {"samples_per_second", pixels * run.spp / r.kernelSeconds},
      {"estimated_rmse_luminance_x1000", 1000 * std::sqrt(meanVariance)},
      {"mean_alpha", meanAlpha},
      {"statistics_bytes_per_pixel", r.statisticsBytesPerPixel},
      {"devices", devicesJson(r)},
      {"stages", stagesJson(r.stages)},
  };
  if (run.estimator == Estimator::Resampled) report["ris_candidates"] = run.adaptive.risCandidates;
  if (r.devices.size() > 1) {
    report["imbalance_s"] = r.imbalanceSeconds;
    report["imbalance_fraction"] = r.imbalanceSeconds / r.wallSeconds;
  }
  if (isAdaptive(run.method)) {
    // The costs of the kernel without statistics, which runs the last stage.
    nlohmann::json costs;
    for (int k = 0; k < M; ++k) costs[names[k]] = r.costModel->perSample(false)[k];
    report["allocation"] = {
        {"stages", r.stageCount},
        {"pilot_fraction", run.adaptive.pilotFraction},
        {"pool_radius", run.adaptive.poolRadius},
        {"skip_below", run.adaptive.minGain},
        {"costs_s_per_sample", costs},
        {"costs_source", costSourceName(r.costModel->source())},
        {"cost_model", costModelJson(*r.costModel, names)},
        {"fallback_pixels", r.fallbackPixels},
        {"fallback_pixel_fraction", summary.fallbackFraction},
        {"floored_pixels", r.flooredPixels},
        {"floored_pixel_fraction", summary.flooredFraction},
        {"skipped_pixels", r.skippedPixels},
        {"skipped_pixel_fraction", summary.skippedFraction},
    };
    if (methodTraits(run.method).searchesWeights) {
      report["allocation"]["grid_u"] = run.adaptive.gridSize;
      report["allocation"]["grid_selection"] =
          run.method == Method::Exact && run.adaptive.gridRule == GridRule::MaxEntropy
              ? "maximum entropy of normalised lambda ([HS14] Alg. 1 line 13)"
              : "minimum cost x multi-sample variance ([SHS16] eq. 21)";
    }
    if (run.method == Method::Exact) {
      report["allocation"]["skip_image_below"] = run.adaptive.imageGainBelow;
      report["allocation"]["predicted_gain"] = optionalJson(r.predictedGain);
      report["allocation"]["kept_equal_counts"] = r.keptEqualCounts;
    }
    if (methodTraits(run.method).split == Split::Probed)
      report["allocation"]["oracle_probe_spp"] = run.adaptive.oracleSamples;
    else
      report["allocation"]["pilot_weight_mean"] = r.meanPilotWeight;
    if (run.method == Method::Linear)
      report["allocation"]["zero_weight_rule"] = run.adaptive.linearRule == ZeroWeightRule::MinSampleVariance
                                                     ? "min sample variance ([SS23] eq. 19)"
                                                     : "drop most negative ([SS23] Sec. 5.1)";
  }
  if (run.reference) {
    report["reference"] = {{"source", run.reference->source}, {"path", run.reference->path}};
    report["rmse_x1000"] = 1000 * std::sqrt(*summary.mse);
    report["relative_mse"] = *summary.relativeMse;
    // The error against the true image: the reference's own variance taken out.
    report["rmse_x1000_corrected"] = 1000 * std::sqrt(std::max(0.0, summary.corrected->mse));
    report["mse_corrected"] = summary.corrected->mse;
    report["mse_corrected_standard_error"] = summary.corrected->standardError;
    report["reference"]["variance_share"] =
        *summary.mse > 0 ? (*summary.mse - summary.corrected->mse) / *summary.mse : 0.0;
  } else {
    report["reference"] = nullptr;
  }
  return report;
}

}  // namespace misalloc
