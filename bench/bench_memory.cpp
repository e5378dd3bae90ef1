// Memory per pixel of every method: what the public API says a render keeps between
// stages (running sums and stored samples, samplerConfigFor and StageSampler) and
// takes per stage (StagePlan and StageResult), next to what a render of the OpenCL
// Sampler (PoCL by default) and of its OpenMP C++ peer HostSampler actually use.
//
//   build/bench/misalloc_bench_memory [--device cpu] [--size 256] [--spp 200] [--summary FILE.json]
//
// Measured in a child process per method, peer and image size, after a warm-up render
// on a 16x16 image (kernel compilation, PoCL's own allocations): the growth of the
// resident set at its peak during construction and render (VmHWM after clear_refs),
// and the heap still in use by the sampler after the render (glibc mallinfo2; PoCL's
// buffers on a CPU device are glibc allocations too). Two image sizes, size² and
// (size/2)², separate the bytes per pixel from the fixed part, such as the envmap's
// texels and tables that the OpenCL sampler uploads.
#include <fmt/format.h>
#include <malloc.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

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
  int size = 256, spp = 200;
} config;

enum class Peer { OpenCl, OpenMp };

// What one child reports: the sampler's sizes and the bytes it measured.
struct Footprint {
  char device[128] = "";  // OpenCL device name; empty for the OpenMP peer
  int techniqueCount = 0;
  int statSlots = 0;
  double pixels = 0;
  double storedFloats = 0;  // per pixel, padding included
  double kept = 0;          // Rendering::statisticsBytesPerPixel
  double peak = 0;          // resident set growth at its peak
  double alive = 0;         // heap in use after the render, sampler alive
};

// bytes = fixed + perPixel · pixels, through two measurements.
struct Growth {
  double perPixel, fixed;
};

Growth growth(const Footprint& small, const Footprint& large, double Footprint::*bytes) {
  double perPixel = (large.*bytes - small.*bytes) / (large.pixels - small.pixels);
  return {perPixel, large.*bytes - perPixel * large.pixels};
}

double heapInUse() {
  struct mallinfo2 m = mallinfo2();
  return double(m.uordblks + m.hblkhd);
}

// A "Vm...:  N kB" line of /proc/self/status, in bytes.
double statusBytes(const std::string& field) {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind(field + ":", 0) == 0) return std::stod(line.substr(field.size() + 1)) * 1024;
  throw std::runtime_error("no " + field + " in /proc/self/status");
}

// Sets the peak resident set (VmHWM) to the current one (Linux proc(5), clear_refs).
void resetPeakResidentSet() {
  std::ofstream clearRefs("/proc/self/clear_refs");
  clearRefs << "5";
  if (!clearRefs.flush()) throw std::runtime_error("cannot write /proc/self/clear_refs");
}

Scene benchScene(int size) {
  SceneOptions o;
  o.width = o.height = size;
  return makeScene(o);
}

AdaptiveOptions benchOptions(const Scene& scene) {
  AdaptiveOptions options;
  options.costs.assign(scene.techniqueCount(), 1.0);
  return options;
}

std::unique_ptr<StageSampler> makeSampler(Peer peer, const Device* device, const Scene& scene, Method method) {
  SamplerConfig c = samplerConfigFor(method, Estimator::MultiSample, config.spp, benchOptions(scene), scene.techniqueCount());
  if (peer == Peer::OpenCl) return std::make_unique<Sampler>(*device, scene, c);
  return std::make_unique<HostSampler>(scene, c);
}

Footprint measure(Peer peer, Method method, int size) {
  std::unique_ptr<Device> device;
  if (peer == Peer::OpenCl) device = std::make_unique<Device>(openDevice(config.device));
  const Scene scene = benchScene(size);
  {
    const Scene tiny = benchScene(16);
    auto warmUp = makeSampler(peer, device.get(), tiny, method);
    render(*warmUp, method, benchOptions(tiny), config.spp, 1);
  }
  malloc_trim(0);
  const double heapBefore = heapInUse(), residentBefore = statusBytes("VmRSS");
  resetPeakResidentSet();
  auto sampler = makeSampler(peer, device.get(), scene, method);
  Footprint f;
  f.kept = render(*sampler, method, benchOptions(scene), config.spp, 2).statisticsBytesPerPixel;
  f.peak = statusBytes("VmHWM") - residentBefore;
  f.alive = heapInUse() - heapBefore;
  f.pixels = scene.pixelCount();
  if (device) fmt::format_to_n(f.device, sizeof f.device - 1, "{}", device->name());
  f.techniqueCount = scene.techniqueCount();
  f.statSlots = sampler->statSlots();
  f.storedFloats = double(sampler->storedSampleCount()) / f.pixels;
  return f;
}

// Runs `measure` in a child process: each measurement starts from a fresh heap and
// resident set, and no OpenCL or OpenMP state is shared across a fork.
Footprint measureInChild(Peer peer, Method method, int size) {
  int channel[2];
  if (pipe(channel) != 0) throw std::runtime_error("pipe failed");
  pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    close(channel[0]);
    int status = 0;
    try {
      Footprint f = measure(peer, method, size);
      status = write(channel[1], &f, sizeof f) == ssize_t(sizeof f) ? 0 : 1;
    } catch (const std::exception& e) {
      std::cerr << methodName(method) << ": " << e.what() << "\n";
      status = 1;
    }
    _exit(status);
  }
  close(channel[1]);
  Footprint f;
  ssize_t got = read(channel[0], &f, sizeof f);
  close(channel[0]);
  int status = 0;
  waitpid(child, &status, 0);
  if (got != ssize_t(sizeof f) || !WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw std::runtime_error("measuring " + methodName(method) + " failed");
  return f;
}

// Per pixel and stage, the same for every method: the plan's counts and first indices
// and the result's RGB and moments (kept on the host; a device holds them once more).
double stageBytesPerPixel(int M) {
  return M * double(sizeof(int32_t) + sizeof(uint32_t)) + 3 * sizeof(double) + 2.0 * M * sizeof(double);
}

}  // namespace

int main(int argc, char** argv) {
  bench::takeFlags(argc, argv,
                   {{"--device", [](const char* v) { config.device = v; }},
                    {"--size", [](const char* v) { config.size = std::stoi(v); }},
                    {"--spp", [](const char* v) { config.spp = std::stoi(v); }}});
  // [method][peer][small, large]
  std::vector<std::array<std::array<Footprint, 2>, 2>> footprints(allMethods().size());
  for (size_t i = 0; i < footprints.size(); ++i)
    for (Peer peer : {Peer::OpenCl, Peer::OpenMp})
      for (int large : {0, 1})
        footprints[i][int(peer)][large] = measureInChild(peer, allMethods()[i], large ? config.size : config.size / 2);
  const std::string device = footprints[0][0][1].device;
  const int M = footprints[0][0][1].techniqueCount;
  const nlohmann::json sizes = {
      {"device", device}, {"width", config.size}, {"height", config.size}, {"spp", config.spp}};
  std::string computed = fmt::format(
      "Memory per pixel from the public API, {}x{} pixels, {} spp (bytes)\n\n"
      "| method | running sums (slots x 8) | stored samples (floats x 4) | kept between stages | per stage |\n"
      "|---|---|---|---|---|\n",
      config.size, config.size, config.spp);
  nlohmann::json computedJson = {
      {"title", "Memory per pixel from the public API (bytes)"}, {"config", sizes}, {"rows", nlohmann::json::array()}};
  const std::string measured = fmt::format("{}x{} and {}x{} pixels, {} spp, OpenCL device: {}", config.size,
                                           config.size, config.size / 2, config.size / 2, config.spp, device);
  bench::PeerTable peak{"Measured peak resident-set growth during construction and render, per pixel, " + measured,
                        "method", "B/pixel", sizes, false};
  bench::PeerTable alive{"Measured heap still in use after the render (sampler alive), per pixel, " + measured,
                         "method", "B/pixel", sizes, false};
  bench::PeerTable fixed{"Measured peak resident-set growth, fixed part (independent of pixels), " + measured, "method",
                         "MB", sizes, false};
  for (size_t i = 0; i < footprints.size(); ++i) {
    const std::string name = methodName(allMethods()[i]);
    const auto& [cl, mp] = footprints[i];
    const Footprint& api = cl[1];
    const double sums = api.statSlots * sizeof(double), stored = api.storedFloats * sizeof(float);
    computed += fmt::format("| {} | {:.0f} | {:.0f} | {:.0f} | {:.0f} |\n", name, sums, stored, api.kept,
                            stageBytesPerPixel(M));
    computedJson["rows"].push_back({{"name", name},
                                    {"running_sums", sums},
                                    {"stored_samples", stored},
                                    {"kept_between_stages", api.kept},
                                    {"per_stage", stageBytesPerPixel(M)},
                                    {"unit", "B/pixel"}});
    Growth clPeak = growth(cl[0], cl[1], &Footprint::peak), mpPeak = growth(mp[0], mp[1], &Footprint::peak);
    peak.rows.push_back({name, clPeak.perPixel, mpPeak.perPixel});
    alive.rows.push_back(
        {name, growth(cl[0], cl[1], &Footprint::alive).perPixel, growth(mp[0], mp[1], &Footprint::alive).perPixel});
    fixed.rows.push_back({name, clPeak.fixed / 1e6, mpPeak.fixed / 1e6});
  }
  std::cout << computed << "\n" << peak.markdown() << "\n" << alive.markdown() << "\n" << fixed.markdown();
  bench::writeSummary({computedJson, peak.json(), alive.json(), fixed.json()});
}
