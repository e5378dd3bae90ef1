// Samples per second of each technique and of the MIS estimator: kernels/sample.cl on
// an OpenCL device (PoCL by default) side by side, in one run, with its OpenMP C++
// peer (HostSampler: the same estimator compiled by g++ -O3 -march=native).
//
//   build/bench/misalloc_bench [--device cpu] [--size 256] [--spp 64] [google benchmark flags]
//
// Ends with a Markdown table of medians and the PoCL/OpenMP ratio.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cstring>
#include <iostream>
#include <map>
#include <memory>

#include "cl/Device.h"
#include "render/Method.h"
#include "render/Sampler.h"
#include "render/Scene.h"

using namespace misalloc;

namespace {

struct Config {
  std::string device = "cpu";
  int size = 256, spp = 64;
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
};

Scene benchScene(EnvmapSampler sampler) {
  SceneOptions o;
  o.width = o.height = config.size;
  o.sampler = sampler;
  return makeScene(o);
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
  Sampler sampler(device(), scene);
  runStages(state, sampler, singleStagePlan(scene, v.method, config.spp));
}

void benchOpenMp(benchmark::State& state, const Variant& v) {
  Scene scene = benchScene(v.sampler);
  HostSampler sampler(scene);
  runStages(state, sampler, singleStagePlan(scene, v.method, config.spp));
}

// Keeps the median samples/s of every benchmark for the closing table.
class MedianCollector : public benchmark::ConsoleReporter {
 public:
  std::map<std::string, double> medians;
  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.aggregate_name == "median") medians[r.run_name.function_name] = r.counters.at("samples/s").value;
    ConsoleReporter::ReportRuns(runs);
  }
};

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest;
  for (int i = 0; i < argc; ++i) {
    auto value = [&](const char* flag) { return std::strcmp(argv[i], flag) == 0 && i + 1 < argc; };
    if (value("--device"))
      config.device = argv[++i];
    else if (value("--size"))
      config.size = std::stoi(argv[++i]);
    else if (value("--spp"))
      config.spp = std::stoi(argv[++i]);
    else
      rest.push_back(argv[i]);
  }
  int restCount = int(rest.size());
  benchmark::Initialize(&restCount, rest.data());
  for (const Variant& v : kVariants) {
    for (const char* impl : {"opencl", "openmp"}) {
      auto fn = std::string(impl) == "opencl" ? benchOpenCl : benchOpenMp;
      benchmark::RegisterBenchmark(fmt::format("{}/{}", impl, v.name).c_str(),
                                   [fn, &v](benchmark::State& s) { fn(s, v); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime()
          ->MinTime(0.5)
          ->Repetitions(5)
          ->ReportAggregatesOnly(true);
    }
  }
  MedianCollector reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  std::cout << fmt::format("\nSampling, {}x{} pixels, {} spp, OpenCL device: {}\n\n", config.size, config.size,
                           config.spp, device().name())
            << "| technique | OpenCL Msample/s | OpenMP Msample/s | ratio |\n|---|---|---|---|\n";
  for (const Variant& v : kVariants) {
    auto cl = reporter.medians.find("opencl/" + v.name), mp = reporter.medians.find("openmp/" + v.name);
    if (cl == reporter.medians.end() || mp == reporter.medians.end()) continue;
    std::cout << fmt::format("| {} | {:.1f} | {:.1f} | {:.2f} |\n", v.name, cl->second * 1e-6, mp->second * 1e-6,
                             cl->second / mp->second);
  }
  benchmark::Shutdown();
}
