// How the time of a render grows with its size: MIS equal (alias) renders through
// render(), against the pixel count at a fixed spp and against spp at a fixed pixel
// count, the OpenCL Sampler (PoCL by default) side by side, in one run, with its OpenMP
// C++ peer HostSampler.
//
//   build/bench/misalloc_bench_scaling [--device cpu] [--sizes 64,128,256,512] [--spp 64]
//                                      [--spps 16,32,64,128,256] [--size 256]
//                                      [--summary FILE.json] [google benchmark flags]
//
// Ends with the median time per render at every size and the slope of a least-squares
// line through log time against log size: 1 is linear; below 1, fixed costs per render
// (launches, transfers, per-pixel planning) still weigh at the small end.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <sstream>

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
  std::vector<int> sizes{64, 128, 256, 512}, spps{16, 32, 64, 128, 256};
  int spp = 64, size = 256;
} config;

// One point of a sweep: a square image of `size`² pixels rendered with `spp`.
struct Point {
  int size, spp;
  double x;  // the swept quantity: pixels or spp
  std::string name() const { return fmt::format("{}x{} px, {} spp", size, size, spp); }
};

std::vector<Point> pixelSweep() {
  std::vector<Point> points;
  for (int s : config.sizes) points.push_back({s, config.spp, double(s) * s});
  return points;
}

std::vector<Point> sppSweep() {
  std::vector<Point> points;
  for (int n : config.spps) points.push_back({config.size, n, double(n)});
  return points;
}

// "64,128,256" as integers.
std::vector<int> integers(const std::string& list) {
  std::vector<int> out;
  std::stringstream items(list);
  for (std::string item; std::getline(items, item, ',');) out.push_back(std::stoi(item));
  return out;
}

const Device& device() {
  static const Device d = openDevice(config.device);
  return d;
}

// Scenes are shared by both peers and by both sweeps; each is built once.
const Scene& sceneOfSize(int size) {
  static std::map<int, std::unique_ptr<Scene>> scenes;
  auto& scene = scenes[size];
  if (!scene) {
    SceneOptions o;
    o.width = o.height = size;
    scene = std::make_unique<Scene>(makeScene(o));
  }
  return *scene;
}

void renderRepeatedly(benchmark::State& state, StageSampler& sampler, int spp) {
  render(sampler, Method::Equal, {}, spp, 1);  // warm-up: first-launch costs are not render time
  uint64_t seed = 2;
  for (auto _ : state) benchmark::DoNotOptimize(render(sampler, Method::Equal, {}, spp, seed++).image.rgb.data());
  state.counters["s/render"] =
      benchmark::Counter(1, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void benchOpenCl(benchmark::State& state, Point p) {
  Sampler sampler(device(), sceneOfSize(p.size));
  renderRepeatedly(state, sampler, p.spp);
}

void benchOpenMp(benchmark::State& state, Point p) {
  HostSampler sampler(sceneOfSize(p.size));
  renderRepeatedly(state, sampler, p.spp);
}

// Slope of the least-squares line through (log x, log t).
double logLogSlope(const std::vector<double>& x, const std::vector<double>& t) {
  double n = double(x.size()), sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    double lx = std::log(x[i]), ly = std::log(t[i]);
    sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// The slope of each peer's times over all points of a sweep, and over its upper half,
// where fixed costs weigh least.
void addSlopes(bench::PeerTable& slopes, const std::string& sweep, const std::vector<Point>& points,
               const bench::PeerTable& times) {
  std::vector<Point> measured;
  std::vector<double> x, openCl, openMp;
  for (const Point& p : points)
    for (const auto& row : times.rows)
      if (row.name == p.name()) {
        measured.push_back(p);
        x.push_back(p.x);
        openCl.push_back(row.openCl);
        openMp.push_back(row.openMp);
      }
  auto fit = [&](size_t from) {
    auto tail = [from](const std::vector<double>& v) { return std::vector<double>(v.begin() + from, v.end()); };
    std::string range = from == 0 ? "all points" : "from " + measured[from].name();
    slopes.rows.push_back({fmt::format("time vs {}, {}", sweep, range), logLogSlope(tail(x), tail(openCl)),
                           logLogSlope(tail(x), tail(openMp))});
  };
  if (x.size() >= 2) fit(0);
  if (x.size() >= 4) fit(x.size() / 2);
}

// Registers the points not registered yet (the sweeps share one) and returns all
// their names.
std::vector<std::string> registerSweep(const std::vector<Point>& points) {
  static std::set<std::string> registered;
  std::vector<std::string> names;
  for (const Point& p : points) {
    names.push_back(p.name());
    if (!registered.insert(p.name()).second) continue;
    bench::registerPeers(
        p.name(), [p](benchmark::State& s) { benchOpenCl(s, p); }, [p](benchmark::State& s) { benchOpenMp(s, p); });
  }
  return names;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<char*> rest = bench::takeFlags(argc, argv,
                                             {{"--device", [](const char* v) { config.device = v; }},
                                              {"--sizes", [](const char* v) { config.sizes = integers(v); }},
                                              {"--spp", [](const char* v) { config.spp = std::stoi(v); }},
                                              {"--spps", [](const char* v) { config.spps = integers(v); }},
                                              {"--size", [](const char* v) { config.size = std::stoi(v); }}});
  bench::initialize(rest);
  std::vector<std::string> pixelNames = registerSweep(pixelSweep()), sppNames = registerSweep(sppSweep());
  bench::MedianCollector reporter("s/render");
  benchmark::RunSpecifiedBenchmarks(&reporter);
  const nlohmann::json common = {{"device", device().name()}, {"method", "equal"}, {"envmap_sampler", "alias"}};
  nlohmann::json pixelConfig = common, sppConfig = common, slopeConfig = common;
  pixelConfig.update({{"sizes", config.sizes}, {"spp", config.spp}});
  sppConfig.update({{"width", config.size}, {"height", config.size}, {"spps", config.spps}});
  slopeConfig.update({{"sizes", config.sizes}, {"spp", config.spp}, {"size", config.size}, {"spps", config.spps}});
  bench::PeerTable pixels{fmt::format("MIS equal (alias) render time against pixels, {} spp, OpenCL device: {}",
                                      config.spp, device().name()),
                          "image", "ms/render", pixelConfig};
  bench::PeerTable spps{fmt::format("MIS equal (alias) render time against spp, {}x{} pixels, OpenCL device: {}",
                                    config.size, config.size, device().name()),
                        "image", "ms/render", sppConfig};
  pixels.addMedians(reporter, pixelNames, 1e-3);
  spps.addMedians(reporter, sppNames, 1e-3);
  bench::PeerTable slopes{"Fitted log-log slopes of render time (1 = linear)", "fit", "slope", slopeConfig, false};
  addSlopes(slopes, "pixels", pixelSweep(), pixels);
  addSlopes(slopes, "spp", sppSweep(), spps);
  bench::finish({pixels, spps, slopes});
}
