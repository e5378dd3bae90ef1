// What the envmap pdf of [Kar19] costs: building each map's tables (texel probabilities
// and the alias table or CDFs) with the plain, the compensated and the optimal pdf (its
// bank for seed000 at 256×256), against one 256×256, 200 spp `equal` render of the
// default scene. The compensated pdf adds L̄ and the subtraction of eq. 14 to the
// build; sampling with it should cost what sampling with the plain pdf does (the same
// kernel reads tables of the same size), which the renders of each map with each pdf
// check. The optimal pdf's sampler draws a block, then a texel in it. Run with interleaved repetitions, so that a
// machine whose load changes slows both pdfs alike:
//
//   build/bench/misalloc_bench_envmap_pdf [--device cpu] --benchmark_repetitions=3
//       --benchmark_enable_random_interleaving=true [google benchmark flags]
#include <benchmark/benchmark.h>

#include <map>

#include "cl/Device.h"
#include "render/Render.h"
#include "sampling/Sampler.h"
#include "scene/Scene.h"

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
  const BrdfGrid grid = makeBrdfGrid("seed000", 256, 256);
  for (auto _ : state)
    benchmark::DoNotOptimize(parsed.optimal() ? buildOptimalEnvmapTables(envmap, sampler, grid, {0, 0, 1})
                                              : buildEnvmapTables(envmap, sampler, parsed));
}

// One 256×256, 200 spp `equal` render of `map` × seed000 with `pdf`, per iteration. Both
// pdfs run the same kernel on tables of the same size: their times should agree, so
// that equal samples are equal time, as [Kar19] Sec. 7 reports.
void benchRender(benchmark::State& state, const std::string& map, const std::string& pdf) {
  static const Device device = openDevice(deviceSpec);
  SceneOptions o;
  o.envmap = map;
  o.width = o.height = 256;
  o.envmapPdf = parseEnvmapPdf(pdf);
  const Scene scene = makeScene(o);
  Sampler sampler(device, scene, samplerConfigFor(Method::Equal, Estimator::MultiSample, 200, {}, scene.techniqueCount()));
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
    for (const char* pdf : {"plain", "compensated", "optimal"})
      for (EnvmapSampler sampler : {EnvmapSampler::Alias, EnvmapSampler::Cdf})
        benchmark::RegisterBenchmark(
            ("tables/" + map + "/" + pdf + (sampler == EnvmapSampler::Cdf ? "/cdf" : "/alias")).c_str(),
            [map, pdf, sampler](benchmark::State& s) { benchTables(s, map, pdf, sampler); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
  for (const std::string& map : maps)
    for (const char* pdf : {"plain", "compensated", "optimal"})
      benchmark::RegisterBenchmark(("render/" + map + "/" + pdf + "/equal/256x256/200spp").c_str(),
                                   [map, pdf](benchmark::State& s) { benchRender(s, map, pdf); })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
  benchmark::RunSpecifiedBenchmarks();
}
