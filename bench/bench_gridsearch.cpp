// Throughput of the exact allocation's grid search ([HS14] Algorithm 1) in evaluations
// per second (pixels × U × samples): kernels/gridsearch.cl on an OpenCL device (PoCL by
// default) side by side, in one run, with its OpenMP C++ peer (GridSearchReference,
// compiled by g++ -O3 -march=native), for both selection rules. One repetition runs the
// searches of a render: the samples arrive in stages, and a search after each adds
// the stage to the running sums and selects.
//
//   build/bench/misalloc_bench_gridsearch [--device cpu] [--size 256] [--grid-u 160] [--samples 200]
//                                         [--stage 40] [--techniques 2] [--summary FILE.json]
//                                         [google benchmark flags]
//
// Repetitions of the two peers are interleaved. Ends with a Markdown table of medians
// and the OpenCL/OpenMP ratio.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>

#include "Constants.h"
#include "KernelCode.h"
#include "PeerComparison.h"
#include "alloc/GridSearch.h"
#include "cl/Device.h"

using namespace misalloc;

namespace {

struct Config {
  std::string device = "cpu";
  int size = 256, gridSize = kDefaultGridSize, samples = 200, stage = 40, techniques = 2;
} config;

const std::pair<const char*, GridRule> kRules[] = {
    {"min cost x variance", GridRule::MinCostVariance},
    {"max entropy", GridRule::MaxEntropy},
};

const Device& device() {
  static const Device d = openDevice(config.device);
  return d;
}

int pixelCount() { return config.size * config.size; }

int stageCount() { return (config.samples + config.stage - 1) / config.stage; }

StoredSampleLayout stageLayout(int stage) {
  return StoredSampleLayout{pixelCount(), config.techniques, config.stage,
                            std::min(config.stage, config.samples - stage * config.stage)};
}

// Every pixel integrates its own f(x) = x^e + b on [0, 1] with the techniques
// p_k = (k + 1) x^k, in stages as kernels/sample.cl stores them: each stage's samples
// technique by technique, counts from the pixel's random mixture. The searches are
// distinct and well posed, and f > 0, so no sample is skipped by the peer.
const std::vector<std::vector<float>>& benchStages() {
  static const std::vector<std::vector<float>> stages = [] {
    const int m = config.techniques;
    std::vector<std::vector<float>> s;
    for (int b = 0; b < stageCount(); ++b) s.emplace_back(stageLayout(b).floatCount(), 1.0f);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (int pixel = 0; pixel < int(misalloc::paddedPixelCount(pixelCount())); ++pixel) {
      double exponent = 0.5 + 2 * uniform(rng), offset = 0.05 + 0.5 * uniform(rng), mix = 0.2 + 0.6 * uniform(rng);
      int firstCount = int(mix * config.stage);
      for (int i = 0; i < config.samples; ++i) {
        int b = i / config.stage, j = i % config.stage;
        auto at = [&](int q) -> float& { return s[b][kern::storedSampleIndex(pixel, j, q, config.stage, m)]; };
        int k = j < firstCount ? 0 : 1 + (j - firstCount) * (m - 1) / (config.stage - firstCount);
        double x = std::pow(uniform(rng), 1.0 / (k + 1));
        at(0) = float(k);
        at(1) = pixel < pixelCount() ? float(std::pow(x, exponent) + offset) : 0.0f;
        for (int l = 0; l < m; ++l) at(2 + l) = float((l + 1) * std::pow(x, l));
      }
    }
    return s;
  }();
  return stages;
}

std::vector<double> benchCosts() { return std::vector<double>(config.techniques, 1.0); }

void setRate(benchmark::State& state) {
  int gridSize = makeWeightGrid(config.techniques, config.gridSize, benchCosts()).size();
  state.counters["evaluations/s"] = benchmark::Counter(double(pixelCount()) * gridSize * config.samples,
                                                       benchmark::Counter::kIsIterationInvariantRate);
}

// One render's searches: from no samples, one search after each stage.
template <typename Search, typename Stages>
void searchStages(Search& search, const Stages& stages, GridRule rule) {
  search.reset();
  for (int b = 0; b < stageCount(); ++b)
    benchmark::DoNotOptimize(search.run(stages[b], stageLayout(b), benchCosts(), rule).selected.data());
}

void benchOpenCl(benchmark::State& state, GridRule rule) {
  std::vector<cl::Buffer> buffers;
  for (const std::vector<float>& s : benchStages())
    buffers.emplace_back(device().context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, s.size() * sizeof(float),
                         const_cast<float*>(s.data()));
  GridSearch search(device(), config.techniques, pixelCount(), config.gridSize);
  for (auto _ : state) searchStages(search, buffers, rule);
  setRate(state);
}

void benchOpenMp(benchmark::State& state, GridRule rule) {
  GridSearchReference search(config.techniques, pixelCount(), config.gridSize);
  for (auto _ : state) searchStages(search, benchStages(), rule);
  setRate(state);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest =
      bench::takeFlags(argc, argv,
                       {{"--device", [](const char* v) { config.device = v; }},
                        {"--size", [](const char* v) { config.size = std::stoi(v); }},
                        {"--grid-u", [](const char* v) { config.gridSize = std::stoi(v); }},
                        {"--samples", [](const char* v) { config.samples = std::stoi(v); }},
                        {"--stage", [](const char* v) { config.stage = std::stoi(v); }},
                        {"--techniques", [](const char* v) { config.techniques = std::stoi(v); }}});
  bench::initialize(rest);
  std::vector<std::string> names;
  for (const auto& [name, rule] : kRules) {
    GridRule r = rule;
    names.push_back(name);
    bench::registerPeers(
        name, [r](benchmark::State& s) { benchOpenCl(s, r); }, [r](benchmark::State& s) { benchOpenMp(s, r); });
  }
  bench::MedianCollector reporter("evaluations/s");
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const int grid = makeWeightGrid(config.techniques, config.gridSize, benchCosts()).size();
  bench::PeerTable table{
      fmt::format("Grid search, {}x{} pixels, M = {}, U = {}, {} samples in stages of {}, OpenCL device: {}",
                  config.size, config.size, config.techniques, grid, config.samples, config.stage, device().name()),
      "rule",
      "G evaluations/s",
      {{"device", device().name()},
       {"width", config.size},
       {"height", config.size},
       {"techniques", config.techniques},
       {"grid_u", grid},
       {"samples", config.samples},
       {"stage", config.stage}}};
  bench::finish({table.addMedians(reporter, names, 1e9)});
}
