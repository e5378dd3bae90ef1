// Throughput of the exact allocation's grid search (000 Algorithm 1) in evaluations
// per second (pixels × U × samples): kernels/gridsearch.cl on an OpenCL device (PoCL by
// default) side by side, in one run, with its OpenMP C++ peer (gridSearchReference,
// compiled by g++ -O3 -march=native), for both selection rules.
//
//   build/bench/misalloc_bench_gridsearch [--device cpu] [--size 256] [--grid-u 160] [--samples 200]
//                                         [--techniques 2] [google benchmark flags]
//
// Repetitions of the two peers are interleaved. Ends with a Markdown table of medians
// and the OpenCL/OpenMP ratio.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <random>

#include "KernelCode.h"
#include "PeerComparison.h"
#include "alloc/GridSearch.h"
#include "cl/Device.h"

using namespace misalloc;

namespace {

struct Config {
  std::string device = "cpu";
  int size = 256, gridSize = kDefaultGridSize, samples = 200, techniques = 2;
} config;

const std::pair<const char*, GridRule> kRules[] = {
    {"min cost x variance", GridRule::MinCostVariance},
    {"max entropy", GridRule::MaxEntropy},
};

const Device& device() {
  static const Device d = openDevice(config.device);
  return d;
}

StoredSampleLayout benchLayout() {
  return StoredSampleLayout{config.size * config.size, config.techniques, config.samples, config.samples};
}

// Every pixel integrates its own f(x) = x^e + b on [0, 1] with the techniques
// p_k = (k + 1) x^k, in stages of kStageSamples as kernels/sample.cl stores them: each
// stage's samples technique by technique, counts from the pixel's random mixture. The
// searches are distinct and well posed, and f > 0, so no sample is skipped by the peer.
constexpr int kStageSamples = 50;

const std::vector<float>& benchSamples() {
  static const std::vector<float> samples = [] {
    StoredSampleLayout layout = benchLayout();
    const int m = layout.techniqueCount;
    std::vector<float> s(layout.floatCount(), 1.0f);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    for (int pixel = 0; pixel < (layout.pixelCount + 15) / 16 * 16; ++pixel) {
      double exponent = 0.5 + 2 * uniform(rng), offset = 0.05 + 0.5 * uniform(rng), mix = 0.2 + 0.6 * uniform(rng);
      int firstCount = int(mix * kStageSamples);
      for (int i = 0; i < layout.taken; ++i) {
        auto at = [&](int q) -> float& { return s[kern::storedSampleIndex(pixel, i, q, layout.capacity, m)]; };
        int j = i % kStageSamples;
        int k = j < firstCount ? 0 : 1 + (j - firstCount) * (m - 1) / (kStageSamples - firstCount);
        double x = std::pow(uniform(rng), 1.0 / (k + 1));
        at(0) = float(k);
        at(1) = pixel < layout.pixelCount ? float(std::pow(x, exponent) + offset) : 0.0f;
        for (int l = 0; l < m; ++l) at(2 + l) = float((l + 1) * std::pow(x, l));
      }
    }
    return s;
  }();
  return samples;
}

std::vector<double> benchCosts() { return std::vector<double>(config.techniques, 1.0); }

void setRate(benchmark::State& state) {
  StoredSampleLayout layout = benchLayout();
  int gridSize = makeWeightGrid(layout.techniqueCount, config.gridSize, benchCosts()).size();
  state.counters["evaluations/s"] = benchmark::Counter(double(layout.pixelCount) * gridSize * layout.taken,
                                                       benchmark::Counter::kIsIterationInvariantRate);
}

void benchOpenCl(benchmark::State& state, GridRule rule) {
  const std::vector<float>& samples = benchSamples();
  cl::Buffer buffer(device().context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, samples.size() * sizeof(float),
                    const_cast<float*>(samples.data()));
  GridSearch search(device(), config.techniques);
  search.run(buffer, benchLayout(), benchCosts(), config.gridSize, rule);  // warm-up: first-launch JIT
  for (auto _ : state)
    benchmark::DoNotOptimize(search.run(buffer, benchLayout(), benchCosts(), config.gridSize, rule).selected.data());
  setRate(state);
}

void benchOpenMp(benchmark::State& state, GridRule rule) {
  const std::vector<float>& samples = benchSamples();
  for (auto _ : state)
    benchmark::DoNotOptimize(
        gridSearchReference(samples, benchLayout(), benchCosts(), config.gridSize, rule).selected.data());
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
      fmt::format("Grid search, {}x{} pixels, M = {}, U = {}, {} samples, OpenCL device: {}", config.size, config.size,
                  config.techniques, grid, config.samples, device().name()),
      "rule",
      "G evaluations/s",
      {{"device", device().name()},
       {"width", config.size},
       {"height", config.size},
       {"techniques", config.techniques},
       {"grid_u", grid},
       {"samples", config.samples}}};
  bench::finish({table.addMedians(reporter, names, 1e9)});
}
