// One render over several devices (sampling/TiledSampler.h): the same image, bit for bit,
// as on one device of the same arithmetic, every pixel exactly once; a device that fails
// has its tiles run again on the others, and with none left the render stops.
#include <fmt/format.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "Covering.h"
#include "Error.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"
#include "sampling/SamplerChoice.h"
#include "sampling/TiledSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

AdaptiveOptions fixedCosts(const Scene& scene) {
  AdaptiveOptions options;
  options.costs.assign(scene.techniqueCount(), 1.0);  // measured costs differ between runs
  options.stages = 2;                                 // a stage after the first allocation keeps statistics too
  options.oracleSamples = 64;
  return options;
}

Rendering renderOn(SamplerDevices& devices, const Scene& scene, Method method, Estimator estimator, int spp) {
  AdaptiveOptions options = fixedCosts(scene);
  auto sampler =
      devices.makeSampler(scene, samplerConfigFor(method, estimator, spp, options, scene.techniqueCount()), 8);
  return render(*sampler, method, options, spp, 11);
}

bool sameBits(const RgbImage& a, const RgbImage& b) {
  return a.rgb.size() == b.rgb.size() && std::memcmp(a.rgb.data(), b.rgb.data(), a.rgb.size() * sizeof(float)) == 0;
}

// PoCL's CPU device in two sub-devices where it can be split, else twice the whole
// device (two contexts): either way two devices of the same arithmetic.
std::string twoCpuDevices() {
  return testDevice().device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>() >= 2 ? "cpu:2" : "cpu,cpu";
}

// A Sampler whose `failAt`-th launch (counted from 1 since construction's warm-up)
// fails as a lost device would.
class FailingSampler : public Sampler {
 public:
  FailingSampler(const Device& device, const Scene& scene, const SamplerConfig& config, int failAt)
      : Sampler(device, scene, config), failAt_(failAt), launches_(0) {}

 protected:
  StageResult runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) override {
    if (++launches_ == failAt_) throw DeviceError("injected failure");
    return Sampler::runPixels(plan, seed, firstSlot, range);
  }

 private:
  int failAt_, launches_;
};

std::unique_ptr<TiledSampler> withFailingMember(const Scene& scene, const SamplerConfig& config,
                                                const std::vector<int>& failAt) {
  std::vector<std::unique_ptr<StageSampler>> members;
  // The constructor's warm-up launches one or two stages (Sampler::Sampler).
  const int warmUps = keepsStatistics(config) ? 2 : 1;
  for (int f : failAt)
    members.push_back(f > 0 ? std::make_unique<FailingSampler>(testDevice(), scene, config, warmUps + f)
                            : std::make_unique<Sampler>(testDevice(), scene, config));
  return std::make_unique<TiledSampler>(scene, config, std::move(members));
}

}  // namespace

TEST_CASE("two devices render the image of one, bit for bit, with every method", "[devices]") {
  // 40×26 pixels: not a whole number of 16-pixel blocks, so the last tile is partial.
  const Scene two = smallScene("rooitou_park", "seed000", 40, 26);
  const Scene three = smallScene("forest_slope", "seed000", 40, 26, true);
  // The host (C++ reference) computes what PoCL computes, bit for bit (kernels/sample.cl).
  const std::vector<std::string> lists{twoCpuDevices(), "cpu,host"};
  struct Case {
    const std::string* list;
    const Scene* scene;
    Method method;
    Estimator estimator;
  };
  std::vector<Case> cases;
  std::vector<Configuration> settings;
  for (const std::string& list : lists)
    for (const Scene* scene : {&two, &three})
      for (Method method : allMethods()) {
        std::vector<Estimator> estimators{Estimator::MultiSample};
        if (!methodTraits(method).fixesEstimator()) estimators.push_back(Estimator::OneSample);
        // The count-independent weights need every technique sampled (render/RunChecks.h).
        if (method == Method::Equal) estimators.push_back(Estimator::CountIndependent);
        for (Estimator estimator : estimators) {
          cases.push_back({&list, scene, method, estimator});
          settings.push_back({"devices=" + std::string(list == "cpu,host" ? "host" : "cpu"),
                              fmt::format("M={}", scene->techniqueCount()), "method=" + methodName(method),
                              fmt::format("estimator={}", int(estimator))});
        }
      }
  // Pairwise (tests/Covering.h): every method with every estimator, device pair and M;
  // small test size (the sanitizers): of M = 3, equal and exact only.
  SamplerDevices one("cpu");
  std::map<std::string, std::unique_ptr<SamplerDevices>> pairs;
  for (size_t i : configurationsToRun(settings)) {
    const Case& c = cases[i];
    if (smallTestSize() && c.scene == &three && c.method != Method::Equal && c.method != Method::Exact) continue;
    auto& pair = pairs[*c.list];
    if (!pair) pair = std::make_unique<SamplerDevices>(*c.list);
    Rendering a = renderOn(one, *c.scene, c.method, c.estimator, 40);
    Rendering b = renderOn(*pair, *c.scene, c.method, c.estimator, 40);
    INFO(fmt::format("--device {}: {} M={} estimator {}", *c.list, methodName(c.method), c.scene->techniqueCount(),
                     int(c.estimator)));
    CHECK(sameBits(a.image, b.image));
    CHECK(a.alpha == b.alpha);
    REQUIRE(b.devices.size() == 2);
    CHECK(b.devices[0].pixelStages + b.devices[1].pixelStages == a.devices[0].pixelStages);
  }
  REQUIRE(pairs.count("cpu,host") == 1);
  CHECK(pairs["cpu,host"]->name().find(kHostSamplerName) != std::string::npos);
}

TEST_CASE("two devices render the image of one where pairs of pixels cross a tile's edge", "[devices][pairs]") {
  // 15 pixels wide: the tiles of 16 pixels cut rows, so a pair or quad of pixels that
  // shares a table (kernels/pixel_pairs.h) can lie in two tiles, and a device reads the
  // counts of up to three pixels of its tile's neighbour. Exponents 1.3 % apart across
  // the plane: every quad of a row shares, and its table is no pixel's own.
  const Scene scene =
      smallScene("sun", "general:0.3,0.3,50,60", 15, 26, false, EnvmapSampler::Alias, 0, "optimal-pixel");
  SamplerDevices one("cpu"), two(twoCpuDevices());
  for (Method method : {Method::Equal, Method::Heuristic}) {
    INFO(methodName(method));
    Rendering a = renderOn(one, scene, method, Estimator::MultiSample, 40);
    Rendering b = renderOn(two, scene, method, Estimator::MultiSample, 40);
    CHECK(sameBits(a.image, b.image));
  }
}

TEST_CASE("a failed device's tiles run again on the others: the same image", "[devices]") {
  const Scene scene = smallScene("studio_small_03", "seed000", 40, 26);
  int injected = 0;
  for (Method method : {Method::Equal, Method::Heuristic, Method::Exact}) {
    AdaptiveOptions options = fixedCosts(scene);
    const SamplerConfig config = samplerConfigFor(method, Estimator::MultiSample, 48, options, scene.techniqueCount());
    Sampler single(testDevice(), scene, config);
    Rendering expected = render(single, method, options, 48, 5);
    // Fails at its second tile: in the pilot of the adaptive methods, after it ran a
    // tile whose running sums only it held.
    auto tiled = withFailingMember(scene, config, {0, 2});
    Rendering r = render(*tiled, method, options, 48, 5);
    INFO(methodName(method));
    CHECK(sameBits(expected.image, r.image));
    CHECK(expected.alpha == r.alpha);
    REQUIRE(r.devices.size() == 2);
    CHECK(r.devices[0].failure.empty());
    // The tiles go to whichever member asks first: under load (the sanitized tests beside
    // the Release ones) the healthy member can take every tile of a render before the
    // other asks for its second, and then nothing failed.
    CHECK((r.devices[1].failure.empty() || r.devices[1].failure == "injected failure"));
    injected += r.devices[1].failure == "injected failure";
  }
  CHECK(injected > 0);
}

TEST_CASE("with every device failed the render stops with a DeviceError", "[devices]") {
  const Scene scene = smallScene("studio_small_03", "seed000", 40, 26);
  AdaptiveOptions options = fixedCosts(scene);
  const SamplerConfig config =
      samplerConfigFor(Method::Equal, Estimator::MultiSample, 16, options, scene.techniqueCount());
  auto tiled = withFailingMember(scene, config, {1, 1});
  CHECK_THROWS_WITH(render(*tiled, Method::Equal, options, 16, 5),
                    Catch::Contains("every device failed") && Catch::Contains("injected failure"));
}

TEST_CASE("render over a device list reports each device's share and the imbalance", "[devices][cli]") {
  TempDir dir("devices");
  auto out = dir.path / "r.exr", report = dir.path / "r.json";
  auto r =
      runMisalloc(fmt::format("render --envmap cosk:1 --size 48x32 --spp 16 --method equal --device {} "
                              "--out {} --report {} --reference none",
                              twoCpuDevices(), out.string(), report.string()));
  INFO(r.output);
  REQUIRE(r.exitCode == 0);
  nlohmann::json j = nlohmann::json::parse(std::ifstream(report));
  REQUIRE(j["devices"].size() == 2);
  double share = 0;
  for (const auto& d : j["devices"]) share += d["pixel_share"].get<double>();
  CHECK(share == Approx(1.0));
  CHECK(j["imbalance_s"].get<double>() >= 0);
  CHECK(j["imbalance_fraction"].get<double>() < 1);
}

TEST_CASE("device lists that name nothing are refused", "[devices][cli][bad-input]") {
  TempDir dir("devices-bad");
  auto out = dir.path / "r.exr";
  for (const char* list : {"cpu,", "cpu:0", "cpu:x", "cpu:1000", "nonsense"}) {
    auto r = runMisalloc(fmt::format("render --size 8x8 --spp 8 --method equal --device {} --out {} --reference none",
                                     list, out.string()));
    INFO(list << ": " << r.output);
    CHECK(r.exitCode == 2);
    CHECK(r.output.find("--device") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(out));
  }
}
