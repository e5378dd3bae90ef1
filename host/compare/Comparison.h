#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "Interruption.h"
#include "render/Method.h"
#include "render/Render.h"
#include "scene/Scene.h"

namespace misalloc {

// A method a case does not run, and why.
struct LeftOutMethod {
  Method method;
  std::string why;
};

// One scene of a comparison, with the label that names its column and its folder.
struct CompareCase {
  std::string label;
  SceneOptions scene;
  std::vector<LeftOutMethod> leftOut;        // methods biased with this case's pdf, or without its weights
  std::vector<int> repeats;                  // the repeats this process runs, ascending (compare/ShardUnit.h)
  MisWeights weights = MisWeights::Balance;  // of every method's multi-sample stages (--weights)
};

// The methods of `methods` that `c` runs, in that order.
std::vector<Method> caseMethods(const CompareCase& c, const std::vector<Method>& methods);

struct CompareOptions {
  std::vector<CompareCase> cases;
  std::vector<Method> methods;
  std::vector<int> budgets;  // spp, ascending
  int repeats = 4;           // independent seeds per (method, budget)
  uint64_t seed = 1;         // repeat r uses seed + r
  int tableBudget = 200;     // the spp of the Table 5.2 layout (the nearest budget)
  AdaptiveOptions adaptive;  // costs empty: each sampler's model from the cost cache (render/CostCache.h)
  std::string device = "auto";
  int localSize = 0;  // 0: each device's own (cl/LaunchShape.h)
  int referenceSpp = 16384;
  std::string cacheDir;
  std::string outDir;
};

// What one render measured.
struct RunRecord {
  std::string caseLabel;
  Method method = Method::Equal;
  int budget = 0;
  int repeat = 0;
  uint64_t seed = 0;
  std::string node;  // the host it ran on: timings compare only within one node
  double wallSeconds = 0, kernelSeconds = 0, allocationSeconds = 0, hostSeconds = 0;
  // Against the reference: `mse` corrected for the reference's own variance (what every
  // table, curve and speed-up uses; one repeat's may be below 0), with its standard
  // error, and the raw MSE.
  double mse = 0, mseStandardError = 0, rawMse = 0, relativeMse = 0;
  std::vector<double> meanAlpha;       // per technique
  double fallbackFraction = 0;         // pixels where an allocation rule fell back
  double flooredFraction = 0;          // pixels whose counts were raised to one per technique
  double skippedFraction = 0;          // pixels the skip rule kept at equal weights
  double weightsFallbackFraction = 0;  // optimal weights: pixels a stage left at the balance heuristic
  double statisticsBytesPerPixel = 0;
  std::optional<double> predictedGain;  // exact: the pilot's whole-image prediction (Rendering)
  bool keptEqualCounts = false;         // exact: the whole-image rule kept equal counts
  std::vector<StageTiming> stages;      // kernel times, predicted and measured
  std::string costSource;               // adaptive methods: their cost model's (costSourceName)

  // 1/(MSE × time): what a method buys per second.
  double efficiency() const { return 1.0 / (mse * wallSeconds); }
};

// What a case shares across its runs.
struct CaseInfo {
  std::string label;
  nlohmann::json scene;
  std::vector<std::string> techniques;
  std::vector<double> costs;
  std::string costSource;  // "--cost", or the cost cache's calibrations (render/CostCache.h)
  std::string referenceSource;
  double referenceVariance = 0;  // its own error: Var(r), mean over pixels and channels
  std::string device;
  std::vector<LeftOutMethod> leftOut;
  std::vector<int> repeats;  // those its runs are of: a shard's, or all
  MisWeights weights = MisWeights::Balance;
};

struct Comparison {
  std::vector<CaseInfo> cases;
  std::vector<RunRecord> runs;
  bool interrupted = false;  // runs holds only what finished
};

// Every case × budget × repeat (the case's own) × method, in that order. Writes each repeat-0 render's
// image and α map (EXR + PNG) under outDir/<case>/ as it goes, and the runs so far to
// outDir/runs.{json,csv} after each one, all atomically. Stops after the render in
// flight when `guard` reports SIGINT or SIGTERM (Comparison::interrupted).
Comparison runComparison(const CompareOptions& options, InterruptionGuard& guard);

// A case as runs.json lists it (every figure as a double keeps it).
nlohmann::json caseInfoJson(const CaseInfo& info);

// runs.json and runs.csv: the cases and the runs so far, written atomically.
void writeRuns(const std::string& outDir, const Comparison& comparison);

// Throws InputError for a budget that some adaptive method cannot split into a pilot
// and its stages, and for an empty or unknown list.
void validateCompareOptions(const CompareOptions& options);

// The file names of a case's repeat-0 outputs, relative to outDir.
std::string imagePath(const std::string& caseLabel, Method method, int budget);  // .exr; .png beside
std::string alphaMapPath(const std::string& caseLabel, Method method, int budget);

}  // namespace misalloc
