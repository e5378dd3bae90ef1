// The sampling kernel's work-group size per device (host/cl/LaunchShape.h): fake GPU and
// CPU limits, --local-size overrides, PoCL's real limits, and the local-memory formula
// against what PoCL reports for the built kernel.
#include <array>
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "Covering.h"
#include "Error.h"
#include "SceneFixtures.h"
#include "TestDevice.h"
#include "TestSize.h"
#include "cl/LaunchShape.h"
#include "render/Render.h"
#include "sampling/HostSampler.h"

using namespace misalloc;
using namespace misalloc::test;

namespace {

constexpr uint64_t k48KiB = 48 * 1024;

DeviceLimits gpu(size_t maxWorkGroupSize = 1024, uint64_t localMemBytes = k48KiB, size_t preferredMultiple = 32) {
  return DeviceLimits{false, maxWorkGroupSize, localMemBytes, preferredMultiple};
}

// The running sums of a method's sampler on a scene of M techniques.
int statSlotsOf(Method method, bool split) {
  Scene scene = smallScene("cosk:3", "uniform:0.5,0.5,10", 4, 4, split);
  HostSampler sampler(scene,
                      samplerConfigFor(method, Estimator::MultiSample, 64, AdaptiveOptions{}, scene.techniqueCount()));
  return sampler.statSlots();
}

std::function<size_t(int)> sampleBytes(int statSlots) {
  return [statSlots](int size) {
    return sampleKernelLocalBytes(size, statSlots, true, kern::pixelRowCount(0, 2, 0, 0, 0, 0));
  };
}

bool hasFp64(const cl::Device& device) {
  return device.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
}

}  // namespace

TEST_CASE("launch shape: sampleStage's local memory: 9 sums, the running sums, the pixel's rows, the pass counts",
          "[launch]") {
  CHECK(sampleKernelLocalBytes(8, 0, true, 10) == 8 * (9 * 8 + 11 * 4));
  CHECK(sampleKernelLocalBytes(256, 15, true, 10) == 256 * (24 * 8 + 11 * 4));
  CHECK(sampleKernelLocalBytes(64, 6, false, 10) == 64 * (15 * 4 + 11 * 4));
  CHECK(sampleKernelLocalBytes(8, 20, true, 16) == 8 * (29 * 8 + 17 * 4));  // optimal weights, M = 2
  // The pixel's rows: BRDF (4), normal (3), mirror direction (3), counts (3), first
  // indices (3); 3M coefficients; 3 product; the optimal pdf per pixel's CDF over its
  // cells (cells + 1), its scratch (2 × cells) and 4 sums per chunk of cells; the
  // product's CDF over the same cells (cells + 1); the share columns' masses, 3 per cell,
  // after the product's rows, which they keep.
  CHECK(kern::pixelRowCount(0, 2, 0, 0, 0, 0) == 16);
  CHECK(kern::pixelRowCount(1, 2, 0, 0, 0, 0) == 22);
  CHECK(kern::pixelRowCount(1, 3, 1, 0, 0, 0) == 28);
  CHECK(kern::pixelRowCount(0, 2, 0, 128, 0, 0) == 16 + 129 + 256 + 4 * MA_PIXEL_CHUNKS);
  CHECK(kern::pixelRowCount(0, 3, 0, 128, 1, 0) == 16 + 129 + 256 + 4 * MA_PIXEL_CHUNKS + 129);
  CHECK(kern::pixelRowCount(0, 2, 0, 128, 0, 1) == 16 + 129 + 256 + 4 * MA_PIXEL_CHUNKS + 129 + 3 * 128);
  CHECK(kern::pixelRowCount(0, 3, 0, 128, 1, 1) == 16 + 129 + 256 + 4 * MA_PIXEL_CHUNKS + 129 + 3 * 128);
  static_assert(MA_PIXEL_SHARE_MASS_ROWS(1) == MA_MAX_BANK_SHARES, "a mass per share column and cell");
  // samplePixelStage: each pixel's rows in a power-of-two block, then one pixel's rows
  // two words apart (and its index), 5 terms of 8 passes a lane and the sums.
  CHECK(kern::pixelRowBlock(16) == 256);
  CHECK(kern::pixelRowBlock(1024) == 1024);
  CHECK(kern::pixelRowBlock(1025) == 2048);
  CHECK(kern::pixelRowBlock(1 << 20) == 1 << 20);
  CHECK(pixelStageLocalBytes(16, 16, 1643) == 16 * 2048 * 4 + 1644 * 2 * 4 + 5 * 8 * 16 * 4 + 16 * 8);
  CHECK(pixelStageLocalBytes(16, 4, 1643) == 4 * 2048 * 4 + 1644 * 2 * 4 + 5 * 8 * 16 * 4 + 16 * 8);
}

TEST_CASE("launch shape: a 48 KiB GPU runs 256 work-items with few running sums, fewer with many", "[launch]") {
  const int few = statSlotsOf(Method::Heuristic, false), many = statSlotsOf(Method::Linear, true);
  REQUIRE(few == 6);
  REQUIRE(many == 15);
  LaunchShape wide = chooseLocalSize(gpu(), sampleBytes(few));
  CHECK(wide.localSize == 256);
  CHECK(wide.why == "GPU: 256 work-items, 47 KiB of 48 KiB local memory");
  // 256 × (24 doubles + 17 ints) = 65 KiB: over.
  LaunchShape narrow = chooseLocalSize(gpu(), sampleBytes(many));
  CHECK(narrow.localSize == 128);
  CHECK(narrow.why ==
        "GPU: 128 work-items, 32.5 KiB of 48 KiB local memory; 256 would need 65 KiB of local memory, the device has "
        "48 KiB");
}

TEST_CASE("launch shape: a GPU's work-group limit and lockstep width bound the size", "[launch]") {
  LaunchShape capped = chooseLocalSize(gpu(64), sampleBytes(0));
  CHECK(capped.localSize == 64);
  CHECK(capped.why ==
        "GPU: 64 work-items, 8.8 KiB of 48 KiB local memory; 128 exceeds the device's 64 work-items "
        "per group");
  // A wavefront of 64 skips 32; below every preferred size the largest that fits runs.
  CHECK(chooseLocalSize(gpu(1024, k48KiB, 64), sampleBytes(0)).localSize == 256);
  CHECK(chooseLocalSize(gpu(1024, 5120, 64), sampleBytes(0)).localSize == 32);
  CHECK(chooseLocalSize(gpu(16), sampleBytes(0)).localSize == 16);
  CHECK_THROWS_AS(chooseLocalSize(gpu(1024, 16), sampleBytes(0)), DeviceError);
}

TEST_CASE("launch shape: a CPU runs 8 work-items (docs/pocl.md rule 4)", "[launch]") {
  DeviceLimits cpu{true, 4096, 4u << 20, 1};
  LaunchShape shape = chooseLocalSize(cpu, sampleBytes(15));
  CHECK(shape.localSize == 8);
  CHECK(shape.why.rfind("CPU: 8 work-items", 0) == 0);
}

TEST_CASE("launch shape: --local-size is taken if it fits and refused naming the limit if not", "[launch]") {
  LaunchShape given = chooseLocalSize(gpu(), sampleBytes(15), 64);
  CHECK(given.localSize == 64);
  CHECK(given.why == "GPU: 64 work-items as --local-size asked, 16.2 KiB of 48 KiB local memory");
  try {
    chooseLocalSize(gpu(), sampleBytes(15), 256);
    FAIL("an override that needs more local memory than the device has was taken");
  } catch (const DeviceError& e) {
    CHECK(std::string(e.what()) ==
          "--local-size 256: the sampling kernel does not fit this GPU: 256 would need 65 KiB of local memory, the "
          "device has 48 KiB");
  }
  CHECK_THROWS_WITH(chooseLocalSize(gpu(512), sampleBytes(0), 1024),
                    "--local-size 1024: the sampling kernel does not fit this GPU: 1024 exceeds the device's 512 "
                    "work-items per group");
  CHECK_THROWS_AS(chooseLocalSize(gpu(), sampleBytes(0), -1), InputError);
}

TEST_CASE("launch shape: PoCL's CPU device: its limits, and 8 work-items", "[launch]") {
  DeviceLimits limits = deviceLimits(testDevice().device);
  CHECK(limits.cpu);
  CHECK(limits.maxWorkGroupSize >= 8);
  CHECK(limits.localMemBytes > 0);
  CHECK(limits.preferredMultiple == 1);
  CHECK(chooseLocalSize(limits, sampleBytes(15)).localSize == 8);
}

TEST_CASE("launch shape: sampleKernelLocalBytes is what PoCL allocates for the built sampleStage", "[launch]") {
  // The techniques (the BRDF as one, split, or with the product), the running sums of a
  // method, the weights, the optimal pdf per pixel's rows and the work-group size each
  // change the kernel's local arrays: a pairwise covering set of them (tests/Covering.h),
  // every one with MISALLOC_TEST_SIZE=exhaustive.
  const Method methods[] = {Method::Equal, Method::Heuristic, Method::Linear};
  std::vector<std::array<int, 5>> cases;
  std::vector<Configuration> settings;
  for (int techniques : {0, 1, 2})
    for (int method = 0; method < 3; ++method)
      for (int optimal : {0, 1})
        for (int pixelPdf : {0, 1})
          for (int localSize : {8, 64}) {
            if (pixelPdf && techniques == 1) continue;  // eq. 9 takes the BRDF as one technique
            cases.push_back({techniques, method, optimal, pixelPdf, localSize});
            settings.push_back({fmt::format("techniques={}", techniques), fmt::format("method={}", method),
                                fmt::format("optimal={}", optimal), fmt::format("pixel={}", pixelPdf),
                                fmt::format("local={}", localSize)});
          }
  const std::vector<size_t> chosen = configurationsToRun(settings);
  const Device& device = testDevice();
  const bool doubleSums = hasFp64(device.device);
  for (size_t c : chosen) {
    const auto [techniques, method, optimal, pixelPdf, localSize] = cases[c];
    const bool split = techniques == 1, product = techniques == 2;
    Scene scene = smallScene("cosk:3", "uniform:0.5,0.5,10", 4, 4, split, EnvmapSampler::Alias, 0,
                             pixelPdf ? "optimal-pixel" : "plain", product);
    if (pixelPdf) REQUIRE(scene.tables.pixelCells > 0);
    AdaptiveOptions options;
    options.weights = optimal ? MisWeights::Optimal : MisWeights::Balance;
    SamplerConfig config =
        samplerConfigFor(methods[method], Estimator::MultiSample, 64, options, scene.techniqueCount());
    const int statSlots = HostSampler(scene, config).statSlots();
    const int pixelRows = samplePixelRows(scene, config);
    CAPTURE(split, product, methodName(methods[method]), optimal, pixelPdf, localSize);
    cl::Kernel kernel(buildProgram(device, "sample.cl", sampleKernelOptions(scene, config, localSize)), "sampleStage");
    CHECK(kernel.getWorkGroupInfo<CL_KERNEL_LOCAL_MEM_SIZE>(device.device) ==
          sampleKernelLocalBytes(localSize, statSlots, doubleSums, pixelRows));
  }
}
