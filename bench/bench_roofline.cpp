// The bounds a sampling kernel cannot pass on this CPU: how many random reads per second
// its cores make into an envmap's own tables (the kernels' buffers), alone and as the
// alias sampler's dependent pair (bucket, then the texel drawn), and how many fp32 fused
// multiply-adds per second they compute. docs/results.md ("Roofline") divides each
// kernel's measured rate by these.
//
//   build/bench/misalloc_bench_roofline [--envmap forest_slope] [--procedural-width 512]
//                                       [--repeats 5]
//
// The pair reads the texel the map's alias table draws: where the map is bright, most
// buckets alias to a few texels, which stay in cache, as in the kernel. The texel reads
// alone are uniform over the map: the worst case of BRDF-sampled directions.
//
// Every thread of OpenMP runs 16 independent streams of reads, so that the rate is the
// memory system's throughput, not one read's latency. Indices come from a xorshift per
// stream; the loops are plain C++ that g++ -O3 -march=native vectorises where it can
// (bench/CMakeLists.txt): the reads then compile to the CPU's own gather instructions.
#include <fmt/format.h>
#include <omp.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <functional>
#include <vector>

#include "scene/Scene.h"

namespace {

constexpr int kStreams = 16;

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Operations per second of `run(steps)` on every thread, the median of `repeats` timings
// of at least 0.3 s each; `perStep` operations per step of one thread.
double rate(const std::function<float(int64_t)>& run, double perStep, int repeats) {
  int64_t steps = 1 << 16;
  std::vector<double> rates;
  float sink = 0;
  while (int(rates.size()) < repeats) {
    auto start = std::chrono::steady_clock::now();
    const int threads = omp_get_max_threads();
#pragma omp parallel reduction(+ : sink)
    sink += run(steps);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds < 0.3) {
      steps *= 2;
      continue;
    }
    rates.push_back(double(steps) * perStep * threads / seconds);
  }
  if (sink == 1.2345f) fmt::print("");  // keeps the sums alive
  return median(rates);
}

uint32_t xorshift(uint32_t x) {
  x ^= x << 13;
  x ^= x >> 17;
  return x ^ (x << 5);
}

// kStreams independent random streams per thread, each taking `steps` steps of
// `read(random)`, which returns what it read; the sum keeps the reads alive.
template <typename Read>
float randomStreams(int64_t steps, Read read) {
  uint32_t state[kStreams];
  float sum[kStreams] = {};
  for (int s = 0; s < kStreams; ++s) state[s] = 0x9e3779b9u * uint32_t(s + 1 + 97 * omp_get_thread_num());
  for (int64_t i = 0; i < steps; ++i)
    for (int s = 0; s < kStreams; ++s) {
      state[s] = xorshift(state[s]);
      sum[s] += read(state[s]);
    }
  float total = 0;
  for (float v : sum) total += v;
  return total;
}

// Random reads of one `Words`-word record of `table` per stream and step.
template <int Words>
float randomReads(const std::vector<uint32_t>& table, int64_t steps) {
  const uint32_t records = uint32_t(table.size() / Words);
  return randomStreams(steps, [&](uint32_t random) {
    const uint32_t* record = table.data() + size_t(uint64_t(random) * records >> 32) * Words;
    float read = 0;
    for (int w = 0; w < Words; ++w) read += float(record[w]);
    return read;
  });
}

// The alias sampler's two dependent reads: a bucket's (acceptance, alias), then the
// four words of the texel drawn, as kernels/envmap.h's sampleAliasTable and envmapTexelHit.
float aliasPairs(const std::vector<uint32_t>& alias, const std::vector<uint32_t>& texels, int64_t steps) {
  const uint32_t buckets = uint32_t(alias.size() / 2);
  return randomStreams(steps, [&](uint32_t random) {
    const uint32_t bucket = uint32_t(uint64_t(random) * buckets >> 32);
    float accept;
    std::memcpy(&accept, &alias[2 * bucket], 4);
    const uint32_t t = float(random & 0xffffffu) * (1.0f / 16777216.0f) < accept ? bucket : alias[2 * bucket + 1];
    float read = 0;
    for (int w = 0; w < 4; ++w) read += float(texels[4 * size_t(t) + w]);
    return read;
  });
}

// The widest vector of fp32 lanes this CPU computes in.
#if defined(__AVX512F__)
constexpr int kLanes = 16;
#elif defined(__AVX__)
constexpr int kLanes = 8;
#else
constexpr int kLanes = 4;
#endif

// Independent fma chains: an fma's latency (4 cycles on Zen and Skylake) times the 2
// pipes that issue them, plus spares against the loop's own instructions, all held in
// registers: 12 chains, a and b take 14 of AVX2's 16 vector registers. Wider vectors
// than the registers, or more chains than they hold, spill to the stack, and the loop
// then measures stores and loads.
constexpr int kChains = 12;

// kChains chains of kLanes-lane fp32 fmas, unrolled, fused (-ffp-contract=fast,
// bench/CMakeLists.txt): enough to fill the FMA pipes.
float fmaChains(int64_t steps) {
  typedef float Lanes __attribute__((vector_size(4 * kLanes)));
  Lanes acc[kChains];
  for (int c = 0; c < kChains; ++c)
    for (int l = 0; l < kLanes; ++l) acc[c][l] = float(c + l) * 1e-3f;
  Lanes a, b;
  for (int l = 0; l < kLanes; ++l) {
    a[l] = 0.999f;
    b[l] = 1e-4f;
  }
  for (int64_t i = 0; i < steps; ++i)
#pragma GCC unroll 16
    for (int c = 0; c < kChains; ++c) acc[c] = acc[c] * a + b;
  float total = 0;
  for (int c = 0; c < kChains; ++c)
    for (int l = 0; l < kLanes; ++l) total += acc[c][l];
  return total;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"misalloc: this CPU's random-read and fma rates, the bounds of the sampling kernels"};
  misalloc::SceneOptions options;
  options.width = options.height = 1;  // the map's tables only
  int repeats = 5;
  app.add_option("--envmap", options.envmap, "the map whose alias table and texels are read");
  app.add_option("--procedural-width", options.proceduralWidth);
  app.add_option("--repeats", repeats);
  CLI11_PARSE(app, argc, argv);

  const misalloc::EnvmapTables tables = misalloc::makeScene(options).tables;
  const std::vector<uint32_t>& alias = tables.aliasTable;
  std::vector<uint32_t> texels(tables.texels.size());
  std::memcpy(texels.data(), tables.texels.data(), 4 * texels.size());
  const double mib = 1.0 / (1 << 20);
  fmt::print("{} threads, envmap {}, {}x{} texels\n\n| what | table | rate |\n|---|---|---|\n", omp_get_max_threads(),
             options.envmap, tables.width, tables.height);
  const double aliasRate = rate([&](int64_t n) { return randomReads<2>(alias, n); }, kStreams, repeats);
  fmt::print("| random reads of an alias bucket (2 words) | {:.1f} MiB | {:.3g} G/s |\n", alias.size() * 4 * mib,
             aliasRate * 1e-9);
  const double texelRate = rate([&](int64_t n) { return randomReads<4>(texels, n); }, kStreams, repeats);
  fmt::print("| random reads of a texel (4 words) | {:.1f} MiB | {:.3g} G/s |\n", texels.size() * 4 * mib,
             texelRate * 1e-9);
  const double pairRate = rate([&](int64_t n) { return aliasPairs(alias, texels, n); }, kStreams, repeats);
  fmt::print("| alias bucket, then the texel drawn | {:.1f} + {:.1f} MiB | {:.3g} G/s |\n", alias.size() * 4 * mib,
             texels.size() * 4 * mib, pairRate * 1e-9);
  const double fmaRate = rate(fmaChains, kChains * kLanes, repeats);
  fmt::print("| fp32 fma ({} chains of {} lanes) | — | {:.3g} G/s = {:.0f} GFLOP/s |\n", kChains, kLanes,
             fmaRate * 1e-9, 2 * fmaRate * 1e-9);
}
