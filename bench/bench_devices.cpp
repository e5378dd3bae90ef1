// One render split across devices (sampling/TiledSampler.h) against each device alone:
// PoCL's CPU device in two 1-core sub-devices (`--device cpu:2`) against one of them and
// against the whole device, and, where a GPU is present, `gpu,cpu` against the sum of
// their rates alone. Interleaved repeats, medians, ratios from one run.
//
//   build/bench/misalloc_bench_devices [--size 256] [--spp 200] [--repeats 5]
//                                      [--methods equal,exact] [--envmap forest_slope]
//
// Every configuration renders the same work: the costs of the cost-aware methods are
// measured once, on the whole CPU device, and used by all.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <iostream>
#include <map>

#include "cl/Device.h"
#include "render/Render.h"
#include "sampling/CostModel.h"
#include "sampling/SamplerChoice.h"
#include "scene/Scene.h"

using namespace misalloc;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

struct Timing {
  std::vector<double> wall, imbalance;
};

// A device list of SamplerDevices, or "one sub-device": the first of `cpu:2` alone.
std::unique_ptr<StageSampler> makeSampler(const std::string& config, const Scene& scene, const SamplerConfig& sc,
                                          std::vector<std::unique_ptr<Device>>& keep) {
  if (config == "cpu:2 [1]") {
    keep.push_back(std::make_unique<Device>(std::move(openSubDevices("cpu", 2).front())));
    keep.back()->whole = nullptr;  // one core for everything, the grid search included
    return std::make_unique<Sampler>(*keep.back(), scene, sc);
  }
  static std::map<std::string, std::unique_ptr<SamplerDevices>> lists;
  auto& devices = lists[config];
  if (!devices) devices = std::make_unique<SamplerDevices>(config);
  return devices->makeSampler(scene, sc, 8);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"misalloc: one render across several OpenCL devices"};
  int size = 256, spp = 200, repeats = 5;
  std::string methodList = "equal,exact", envmap = "forest_slope";
  app.add_option("--size", size);
  app.add_option("--spp", spp);
  app.add_option("--repeats", repeats);
  app.add_option("--methods", methodList);
  app.add_option("--envmap", envmap);
  CLI11_PARSE(app, argc, argv);

  SceneOptions options;
  options.envmap = envmap;
  options.width = options.height = size;
  const Scene scene = makeScene(options);
  std::vector<std::string> configs{"cpu:2 [1]", "cpu", "cpu:2"};
  bool gpu = false;
  for (const auto& [platform, device] : enumerateDevices())
    gpu |= (device.getInfo<CL_DEVICE_TYPE>() & CL_DEVICE_TYPE_GPU) != 0;
  if (gpu) configs.insert(configs.end(), {"gpu", "gpu,cpu"});

  std::vector<std::unique_ptr<Device>> keep;
  AdaptiveOptions adaptive;
  {
    SamplerDevices cpu("cpu");
    // One set of costs for every device list, so that they allocate alike.
    auto plain = cpu.makeSampler(scene, SamplerConfig{}, 8);
    adaptive.costs = plain->costModel().perSample(false);
  }
  std::cout << fmt::format("{} x seed000, {}x{}, {} spp, {} interleaved repeats; costs {:.3g}, {:.3g} s/sample\n\n",
                           envmap, size, size, spp, repeats, adaptive.costs[0], adaptive.costs[1]);
  std::cout << "| method | devices | median wall s | speed-up over one 1-core sub-device | over `cpu` | "
               "imbalance (median, of wall) |\n|---|---|---|---|---|---|\n";
  for (const std::string& name : CLI::detail::split(methodList, ',')) {
    const Method method = parseMethod(name);
    const SamplerConfig sc = samplerConfigFor(method, Estimator::MultiSample, spp, adaptive, scene.techniqueCount());
    std::map<std::string, std::unique_ptr<StageSampler>> samplers;
    for (const auto& c : configs) samplers[c] = makeSampler(c, scene, sc, keep);
    std::map<std::string, Timing> t;
    for (int r = 0; r < repeats + 1; ++r)
      for (const auto& c : configs) {
        Rendering out = render(*samplers[c], method, adaptive, spp, 1 + r);
        if (r == 0) continue;  // the first render of each: first-launch costs
        t[c].wall.push_back(out.wallSeconds);
        t[c].imbalance.push_back(out.imbalanceSeconds / out.wallSeconds);
      }
    const double one = median(t["cpu:2 [1]"].wall), whole = median(t["cpu"].wall);
    for (const auto& c : configs) {
      const double wall = median(t[c].wall);
      std::cout << fmt::format("| {} | {} | {:.4f} | {:.2f}× | {:.2f}× | {:.1f} % |\n", name, c, wall, one / wall,
                               whole / wall, 100 * median(t[c].imbalance));
    }
    if (gpu) {
      const double alone = 1 / median(t["gpu"].wall) + 1 / whole, both = 1 / median(t["gpu,cpu"].wall);
      std::cout << fmt::format("| {} | gpu,cpu against the sum of gpu's and cpu's rates | | {:.2f}× | | |\n", name,
                               both / alone);
    }
  }
  return 0;
}
