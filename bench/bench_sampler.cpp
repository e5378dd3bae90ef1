// Samples per second of each technique and of the MIS estimator: kernels/sample.cl on
// an OpenCL device (PoCL by default) side by side, in one run, with its OpenMP C++
// peer (HostSampler: the same estimator compiled by g++ -O3 -march=native).
//
//   build/bench/misalloc_bench [--device cpu] [--size 256] [--spp 64] [--summary FILE.json]
//                              [--envmap forest_slope] [--procedural-width 512]
//                              [google benchmark flags]
//
// A procedural map a few texels wide (`--envmap constant --procedural-width 16`) keeps
// every table in L1: the kernels' rate without the cost of their table reads, the
// arithmetic side of docs/results.md's roofline.
//
// Ends with a Markdown table of medians and the OpenCL/OpenMP ratio.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <memory>

#include "PeerComparison.h"
#include "cl/Device.h"
#include "render/Method.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"
#include "sampling/Sampler.h"
#include "scene/Scene.h"

using namespace misalloc;

namespace {

struct Config {
  std::string device = "cpu", envmap = "forest_slope";
  int size = 256, spp = 64, proceduralWidth = 512;
} config;

struct Variant {
  std::string name;
  Method method;
  EnvmapSampler sampler;
};

const Variant kVariants[] = {
    {"envmap (alias)", Method::Envmap, EnvmapSampler::Alias},
    {"envmap (cdf)", Method::Envmap, EnvmapSampler::Cdf},
    {"brdf", Method::Brdf, EnvmapSampler::Alias},
    {"MIS equal (alias)", Method::Equal, EnvmapSampler::Alias},
    {"MIS equal (cdf)", Method::Equal, EnvmapSampler::Cdf},
    {fmt::format("ris, {} candidates (alias)", kDefaultRisCandidates), Method::Ris, EnvmapSampler::Alias},
};

Scene benchScene(EnvmapSampler sampler) {
  SceneOptions o;
  o.width = o.height = config.size;
  o.sampler = sampler;
  o.envmap = config.envmap;
  o.proceduralWidth = config.proceduralWidth;
  return makeScene(o);
}

// What a render of the variant's method builds: ris its own estimator.
SamplerConfig configOf(const Variant& v) {
  return samplerConfigFor(v.method, Estimator::MultiSample, config.spp, AdaptiveOptions{});
}

const Device& device() {
  static const Device d = openDevice(config.device);
  return d;
}

void runStages(benchmark::State& state, StageSampler& sampler, const StagePlan& plan) {
  sampler.run(plan, 1);  // warm-up: JIT and first-launch costs are not samples
  uint64_t seed = 2;
  for (auto _ : state) benchmark::DoNotOptimize(sampler.run(plan, seed++).rgb.data());
  state.counters["samples/s"] = benchmark::Counter(double(plan.counts.size() / plan.techniqueCount) * plan.stageSamples,
                                                   benchmark::Counter::kIsIterationInvariantRate);
}

void benchOpenCl(benchmark::State& state, const Variant& v) {
  Scene scene = benchScene(v.sampler);
  Sampler sampler(device(), scene, configOf(v));
  runStages(state, sampler, singleStagePlan(scene, v.method, config.spp));
}

void benchOpenMp(benchmark::State& state, const Variant& v) {
  Scene scene = benchScene(v.sampler);
  HostSampler sampler(scene, configOf(v));
  runStages(state, sampler, singleStagePlan(scene, v.method, config.spp));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest =
      bench::takeFlags(argc, argv,
                       {{"--device", [](const char* v) { config.device = v; }},
                        {"--size", [](const char* v) { config.size = std::stoi(v); }},
                        {"--spp", [](const char* v) { config.spp = std::stoi(v); }},
                        {"--envmap", [](const char* v) { config.envmap = v; }},
                        {"--procedural-width", [](const char* v) { config.proceduralWidth = std::stoi(v); }}});
  bench::initialize(rest);
  std::vector<std::string> names;
  for (const Variant& v : kVariants) {
    names.push_back(v.name);
    bench::registerPeers(
        v.name, [&v](benchmark::State& s) { benchOpenCl(s, v); }, [&v](benchmark::State& s) { benchOpenMp(s, v); });
  }
  bench::MedianCollector reporter("samples/s");
  benchmark::RunSpecifiedBenchmarks(&reporter);
  bench::PeerTable table{fmt::format("Sampling, {}x{} pixels, {} spp, envmap {}, OpenCL device: {}", config.size,
                                     config.size, config.spp, config.envmap, device().name()),
                         "technique",
                         "Msample/s",
                         {{"device", device().name()},
                          {"width", config.size},
                          {"height", config.size},
                          {"spp", config.spp},
                          {"envmap", config.envmap},
                          {"procedural_width", config.proceduralWidth}}};
  bench::finish({table.addMedians(reporter, names, 1e6)});
}
