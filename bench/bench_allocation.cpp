// Time of the allocation step of each adaptive method, in nanoseconds per pixel per
// step: between two stages, reading the statistics back and computing every pixel's
// next-stage counts (Rendering::allocationSeconds over pixels × steps). Whole renders
// through render(), with the OpenCL Sampler (PoCL by default) side by side, in one run,
// with its OpenMP C++ peer HostSampler.
//
//   build/bench/misalloc_bench_allocation [--device cpu] [--size 256] [--spp 64] [--stages 4]
//                                         [--summary FILE.json] [google benchmark flags]
//
// What the two peers differ in: for heuristic, sigma-sqrt-c and linear the allocation
// is the same host C++ code on both sides; only where the running sums and stored
// samples come from differs (a device read-back or a host copy), so their ratios should
// stay near 1. For exact the step is the grid search: kernels/gridsearch.cl against its
// C++ reference, gridSearchReference (-O3 -march=native).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "PeerComparison.h"
#include "cl/Device.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"
#include "sampling/Sampler.h"
#include "scene/Scene.h"

using namespace misalloc;

namespace {

struct Config {
  std::string device = "cpu";
  int size = 256, spp = 64, stages = 4;
} config;

const Method kMethods[] = {Method::Heuristic, Method::SigmaSqrtC, Method::Linear, Method::Exact};

const Device& device() {
  static const Device d = openDevice(config.device);
  return d;
}

const Scene& benchScene() {
  static const Scene scene = [] {
    SceneOptions o;
    o.width = o.height = config.size;
    return makeScene(o);
  }();
  return scene;
}

// Equal costs rather than measured ones: both peers then allocate for the same c_k.
AdaptiveOptions benchOptions() {
  AdaptiveOptions options;
  options.stages = config.stages;
  options.costs.assign(benchScene().techniqueCount(), 1.0);
  return options;
}

// One render per iteration on one sampler (each render starts it afresh).
void renderAndTime(benchmark::State& state, StageSampler& sampler, Method method) {
  const AdaptiveOptions options = benchOptions();
  render(sampler, method, options, config.spp, 1);  // warm-up: the grid search's first launch
  double allocationSeconds = 0;
  int steps = 0;
  uint64_t seed = 2;
  for (auto _ : state) {
    Rendering r = render(sampler, method, options, config.spp, seed++);
    allocationSeconds += r.allocationSeconds;
    steps = r.stageCount - 1;  // the pilot needs no allocation
  }
  state.counters["ns/pixel/step"] = benchmark::Counter(
      allocationSeconds * 1e9 / (double(benchScene().pixelCount()) * steps), benchmark::Counter::kAvgIterations);
}

SamplerConfig benchSamplerConfig(Method method) {
  return samplerConfigFor(method, Estimator::MultiSample, config.spp, benchOptions(), benchScene().techniqueCount());
}

void benchOpenCl(benchmark::State& state, Method method) {
  Sampler sampler(device(), benchScene(), benchSamplerConfig(method));
  renderAndTime(state, sampler, method);
}

void benchOpenMp(benchmark::State& state, Method method) {
  HostSampler sampler(benchScene(), benchSamplerConfig(method));
  renderAndTime(state, sampler, method);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest = bench::takeFlags(argc, argv,
                                             {{"--device", [](const char* v) { config.device = v; }},
                                              {"--size", [](const char* v) { config.size = std::stoi(v); }},
                                              {"--spp", [](const char* v) { config.spp = std::stoi(v); }},
                                              {"--stages", [](const char* v) { config.stages = std::stoi(v); }}});
  bench::initialize(rest);
  std::vector<std::string> names;
  for (Method m : kMethods) {
    names.push_back(methodName(m));
    bench::registerPeers(
        methodName(m), [m](benchmark::State& s) { benchOpenCl(s, m); },
        [m](benchmark::State& s) { benchOpenMp(s, m); });
  }
  bench::MedianCollector reporter("ns/pixel/step");
  benchmark::RunSpecifiedBenchmarks(&reporter);
  bench::PeerTable table{
      fmt::format("Allocation step, {}x{} pixels, {} spp in a pilot and {} stages, OpenCL device: {}", config.size,
                  config.size, config.spp, config.stages, device().name()),
      "method",
      "ns/pixel/step",
      {{"device", device().name()},
       {"width", config.size},
       {"height", config.size},
       {"spp", config.spp},
       {"stages", config.stages}}};
  bench::finish({table.addMedians(reporter, names, 1.0)});
}
