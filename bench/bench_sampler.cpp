// Samples per second of each technique and of the MIS estimator: kernels/sample.cl on
// an OpenCL device (PoCL by default) side by side, in one run, with two OpenMP C++
// peers: HostSampler, its scalar reference, and VectorisedPeer, each technique's
// samples in an `omp simd` loop (bench/CMakeLists.txt has both's flags). The vectorised
// peer runs the balance heuristic of the plain pdf: not RIS, whose resampling loop over
// candidates would be a peer of its own. Before it is timed, its stage is checked against
// HostSampler's, and the run stops where they differ.
//
//   build/bench/misalloc_bench [--device cpu] [--size 256] [--spp 64] [--summary FILE.json]
//                              [--envmap forest_slope] [--procedural-width 512]
//                              [--frames flat|dome|random] [google benchmark flags]
//
// --frames gives the pixels frames of their own (kernels/estimator.h, ShadingPoint): a
// dome seen from above (the normals of a hemisphere, each pixel's neighbours alike), or
// a normal and a view drawn at random per pixel (no two pixels' BRDF samples alike, the
// worst case for the map's cache lines); flat, the default, is [HS14]'s plane.
//
// A procedural map a few texels wide (`--envmap constant --procedural-width 16`) keeps
// every table in L1: the kernels' rate without the cost of their table reads, the
// arithmetic side of docs/results.md's roofline.
//
// Ends with a Markdown table of medians and the OpenCL/OpenMP ratios. Google Benchmark's
// rows also show `kernel samples/s`, the rate by the stage's own kernel time (OpenCL
// events; HostSampler's computation): on a GPU, where the host's readback is most of a
// stage, the two differ by more than 50× (docs/results.md).
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <set>

#include "PeerComparison.h"
#include "VectorisedPeer.h"
#include "cl/Device.h"
#include "render/Method.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"
#include "sampling/Sampler.h"
#include "scene/Scene.h"

using namespace misalloc;

namespace {

struct Config {
  std::string device = "cpu", envmap = "forest_slope", frames = "flat";
  int size = 256, spp = 64, proceduralWidth = 512;
} config;

struct Variant {
  std::string name;
  Method method;
  EnvmapSampler sampler;
  bool vectorisedPeer;  // VectorisedPeer runs its estimator
};

const Variant kVariants[] = {
    {"envmap (alias)", Method::Envmap, EnvmapSampler::Alias, true},
    {"envmap (cdf)", Method::Envmap, EnvmapSampler::Cdf, true},
    {"brdf", Method::Brdf, EnvmapSampler::Alias, true},
    {"MIS equal (alias)", Method::Equal, EnvmapSampler::Alias, true},
    {"MIS equal (cdf)", Method::Equal, EnvmapSampler::Cdf, true},
    {fmt::format("ris, {} candidates (alias)", kDefaultRisCandidates), Method::Ris, EnvmapSampler::Alias, false},
};

// The vectorised peer sums HostSampler's samples in another order. Every term is ≥ 0,
// so sums of N terms then differ by at most about N·2⁻⁵³ relative (1e-14 at 64 spp); a
// single sample one float ulp off would show at 1e-9 or more.
constexpr double kPeerAgreement = 1e-12;

Vec3f normalised(double x, double y, double z) {
  const double len = std::sqrt(x * x + y * y + z * z);
  return {float(x / len), float(y / len), float(z / len)};
}

// Pixel (i, j)'s frame under --frames: seen along z from above.
PixelFrame benchFrame(int i, int j) {
  const Vec3f up{0.0f, 0.0f, 1.0f};
  if (config.frames == "dome") {
    // The hemisphere over the image's inscribed disc; outside it, its rim's normal.
    const double x = 2 * (i + 0.5) / config.size - 1, y = 1 - 2 * (j + 0.5) / config.size;
    const double r2 = x * x + y * y;
    const Vec3f n = r2 < 0.99 ? normalised(x, y, std::sqrt(1 - r2)) : normalised(x, y, 0.1);
    return {n, mirrorDirection(n, up)};
  }
  // random: a normal on the upper hemisphere and a view above its horizon, by a hash of the pixel.
  uint64_t h = (uint64_t(j) * 0x9e3779b97f4a7c15ull) ^ (uint64_t(i) * 0xbf58476d1ce4e5b9ull);
  auto uniform = [&h] {
    h = (h ^ (h >> 31)) * 0x94d049bb133111ebull + 0x2545f4914f6cdd1dull;
    return double(h >> 11) / 9007199254740992.0;
  };
  const Vec3f n = normalised(uniform() - 0.5, uniform() - 0.5, uniform() + 0.1);
  const Vec3f v = normalised(n[0] + uniform() - 0.5, n[1] + uniform() - 0.5, n[2] + 0.2);
  return {n, mirrorDirection(n, v)};
}

Scene benchScene(EnvmapSampler sampler) {
  SceneOptions o;
  o.width = o.height = config.size;
  o.sampler = sampler;
  o.envmap = config.envmap;
  o.proceduralWidth = config.proceduralWidth;
  Scene scene = makeScene(o);
  if (config.frames != "flat")
    for (int j = 0; j < config.size; ++j)
      for (int i = 0; i < config.size; ++i) scene.geometry.pixels[size_t(j) * config.size + i] = benchFrame(i, j);
  return scene;
}

// What a render of the variant's method builds: ris its own estimator.
SamplerConfig configOf(const Variant& v, const Scene& scene) {
  return samplerConfigFor(v.method, Estimator::MultiSample, config.spp, AdaptiveOptions{}, scene.techniqueCount());
}

const Device& device() {
  static const Device d = openDevice(config.device);
  return d;
}

// Times `run(seed)`, a stage of `plan` with a new seed each time.
template <typename RunStage>
void timeStages(benchmark::State& state, const StagePlan& plan, RunStage run) {
  run(1);  // warm-up: JIT and first-launch costs are not samples
  uint64_t seed = 2;
  double kernelSeconds = 0;
  for (auto _ : state) {
    const StageResult result = run(seed++);
    kernelSeconds += result.kernelSeconds;
    benchmark::DoNotOptimize(result.rgb.data());
  }
  const double samples = double(plan.counts.size() / plan.techniqueCount) * plan.stageSamples;
  state.counters["samples/s"] = benchmark::Counter(samples, benchmark::Counter::kIsIterationInvariantRate);
  // The kernel's own rate, by its own clock: on a GPU a stage's time is mostly the
  // host's readback and accumulation (results.md, "The first GPU run").
  if (kernelSeconds > 0)
    state.counters["kernel samples/s"] = benchmark::Counter(samples * double(state.iterations()) / kernelSeconds);
}

void runStages(benchmark::State& state, StageSampler& sampler, const StagePlan& plan) {
  timeStages(state, plan, [&](uint64_t seed) { return sampler.run(plan, seed); });
}

// Of two vectors of one size; NaN where a value is NaN on one side only, which no bound
// accepts.
double largestRelativeDifference(const std::vector<double>& a, const std::vector<double>& b) {
  double largest = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i] == b[i]) continue;
    const double difference = std::abs(a[i] - b[i]) / std::max(std::abs(a[i]), std::abs(b[i]));
    if (std::isnan(difference)) return difference;
    largest = std::max(largest, difference);
  }
  return largest;
}

// Stops the run unless the peer's estimates and moments are HostSampler's, within
// kPeerAgreement per pixel: a faster peer that computes something else compares nothing.
void checkAgainstReference(const Variant& v, const Scene& scene, const bench::VectorisedPeer& peer,
                           const StagePlan& plan) {
  HostSampler reference(scene, configOf(v, scene));
  const StageResult expected = reference.run(plan, 1), got = peer.run(plan, 1);
  const bool sameSizes = expected.rgb.size() == got.rgb.size() && expected.moments.size() == got.moments.size();
  const double estimates = sameSizes ? largestRelativeDifference(expected.rgb, got.rgb) : NAN;
  const double moments = sameSizes ? largestRelativeDifference(expected.moments, got.moments) : NAN;
  if (!(estimates <= kPeerAgreement && moments <= kPeerAgreement)) {
    fmt::print(stderr,
               "misalloc_bench: the vectorised peer's stage of {} differs from HostSampler's: estimates by {:.3g}, "
               "moments by {:.3g} relative (at most {:g})\n",
               v.name, estimates, moments, kPeerAgreement);
    std::exit(1);
  }
  fmt::print("the vectorised peer's stage of {} is HostSampler's within {:.3g} relative\n", v.name,
             std::max(estimates, moments));
}

void benchOpenCl(benchmark::State& state, const Variant& v) {
  Scene scene = benchScene(v.sampler);
  Sampler sampler(device(), scene, configOf(v, scene));
  runStages(state, sampler, singleStagePlan(scene, v.method, config.spp));
}

void benchOpenMp(benchmark::State& state, const Variant& v) {
  Scene scene = benchScene(v.sampler);
  HostSampler sampler(scene, configOf(v, scene));
  runStages(state, sampler, singleStagePlan(scene, v.method, config.spp));
}

void benchOpenMpSimd(benchmark::State& state, const Variant& v) {
  Scene scene = benchScene(v.sampler);
  const StagePlan plan = singleStagePlan(scene, v.method, config.spp);
  const bench::VectorisedPeer peer(scene);
  static std::set<std::string> checked;  // once per variant, not per repetition
  if (checked.insert(v.name).second) checkAgainstReference(v, scene, peer, plan);
  timeStages(state, plan, [&](uint64_t seed) { return peer.run(plan, seed); });
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest =
      bench::takeFlags(argc, argv,
                       {{"--device", [](const char* v) { config.device = v; }},
                        {"--size", [](const char* v) { config.size = std::stoi(v); }},
                        {"--spp", [](const char* v) { config.spp = std::stoi(v); }},
                        {"--envmap", [](const char* v) { config.envmap = v; }},
                        {"--procedural-width", [](const char* v) { config.proceduralWidth = std::stoi(v); }},
                        {"--frames", [](const char* v) { config.frames = v; }}});
  if (config.frames != "flat" && config.frames != "dome" && config.frames != "random") {
    fmt::print(stderr, "misalloc_bench: --frames {}: expected flat, dome or random\n", config.frames);
    return 2;
  }
  bench::initialize(rest);
  std::vector<std::string> names;
  for (const Variant& v : kVariants) {
    names.push_back(v.name);
    std::function<void(benchmark::State&)> simd;
    if (v.vectorisedPeer) simd = [&v](benchmark::State& s) { benchOpenMpSimd(s, v); };
    bench::registerPeers(
        v.name, [&v](benchmark::State& s) { benchOpenCl(s, v); }, [&v](benchmark::State& s) { benchOpenMp(s, v); },
        simd);
  }
  bench::MedianCollector reporter("samples/s");
  benchmark::RunSpecifiedBenchmarks(&reporter);
  bench::PeerTable table{
      fmt::format("Sampling, {}x{} pixels, {} spp, envmap {}, frames {}, OpenCL device: {}", config.size, config.size,
                  config.spp, config.envmap, config.frames, device().name()),
      "technique",
      "Msample/s",
      {{"device", device().name()},
       {"width", config.size},
       {"height", config.size},
       {"spp", config.spp},
       {"envmap", config.envmap},
       {"frames", config.frames},
       {"procedural_width", config.proceduralWidth}}};
  bench::finish({table.addMedians(reporter, names, 1e6)});
}
