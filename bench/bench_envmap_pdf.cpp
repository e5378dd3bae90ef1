// What the envmap pdf of [Kar19] costs: building each map's tables (texel probabilities
// and the alias table or CDFs) with the plain and the compensated pdf, against one
// 256×256, 200 spp `equal` render of the default scene. The compensated pdf adds L̄ and
// the subtraction of eq. 14 to the build; sampling with it costs what sampling with the
// plain pdf does (the same kernel reads the same tables).
//
//   build/bench/misalloc_bench_envmap_pdf [--device cpu] [google benchmark flags]
#include <benchmark/benchmark.h>

#include <map>

#include "cl/Device.h"
#include "render/Render.h"
#include "render/Sampler.h"
#include "render/Scene.h"

using namespace misalloc;

namespace {

std::string deviceSpec = "cpu";

const Envmap& loadedMap(const std::string& name) {
  static std::map<std::string, Envmap> maps;
  auto it = maps.find(name);
  if (it == maps.end()) it = maps.emplace(name, makeEnvmap(resolveEnvmapSpec(name))).first;
  return it->second;
}

void benchTables(benchmark::State& state, const std::string& map, const std::string& pdf, EnvmapSampler sampler) {
  const Envmap& envmap = loadedMap(map);
  const EnvmapPdf parsed = parseEnvmapPdf(pdf);
  for (auto _ : state) benchmark::DoNotOptimize(buildEnvmapTables(envmap, sampler, parsed));
}

void benchRender(benchmark::State& state) {
  static const Device device = openDevice(deviceSpec);
  SceneOptions o;
  o.width = o.height = 256;
  static const Scene scene = makeScene(o);
  Sampler sampler(device, scene, samplerConfigFor(Method::Equal, Estimator::MultiSample, 200, {}));
  render(sampler, Method::Equal, {}, 200, 1);  // warm-up
  uint64_t seed = 2;
  for (auto _ : state) benchmark::DoNotOptimize(render(sampler, Method::Equal, {}, 200, seed++));
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--device" && i + 1 < argc)
      deviceSpec = argv[++i];
    else
      rest.push_back(argv[i]);
  }
  int count = int(rest.size());
  benchmark::Initialize(&count, rest.data());
  std::vector<std::string> maps = shippedEnvmapNames();
  maps.push_back("sun");
  for (const std::string& map : maps)
    for (const char* pdf : {"plain", "compensated"})
      for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf})
        benchmark::RegisterBenchmark(
            ("tables/" + map + "/" + pdf + (sampler == EnvmapSampler::Cdf ? "/cdf" : "/alias")).c_str(),
            [map, pdf, sampler](benchmark::State& s) { benchTables(s, map, pdf, sampler); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  benchmark::RegisterBenchmark("render/equal/256x256/200spp", benchRender)
      ->Unit(benchmark::kMillisecond)
      ->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
}
