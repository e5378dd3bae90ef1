#include "sampling/Sampler.h"

#include <fmt/format.h>

#include <algorithm>
#include <numeric>
#include <type_traits>

#include "Constants.h"
#include "KernelCode.h"
#include "cl/KernelArgs.h"
#include "cl/KernelSource.h"
#include "cl/LaunchShape.h"
#include "sampling/KernelViews.h"
#include "sampling/LaunchWork.h"

namespace misalloc {
namespace {

template <typename T>
cl::Buffer upload(const Device& d, const std::vector<T>& data, cl_mem_flags flags = CL_MEM_READ_ONLY) {
  return cl::Buffer(d.context, flags | CL_MEM_COPY_HOST_PTR, data.size() * sizeof(T), const_cast<T*>(data.data()));
}

// Sums are double where the device has it (ma_acc in kernels/common.h), else float.
// Doubles are read into the vector returned: a copy would fault in a second vector's
// fresh pages in the render's time (about 10 µs a page at its first write on a VM).
template <typename Acc>
std::vector<double> readSums(const Device& d, const cl::Buffer& buffer, size_t first, size_t count) {
  std::vector<Acc> raw(count);
  d.queue.enqueueReadBuffer(buffer, CL_TRUE, first * sizeof(Acc), count * sizeof(Acc), raw.data());
  if constexpr (std::is_same_v<Acc, double>)
    return raw;
  else
    return std::vector<double>(raw.begin(), raw.end());
}

template <typename Acc>
void writeSums(const Device& d, const cl::Buffer& buffer, const std::vector<double>& sums) {
  std::vector<Acc> raw(sums.begin(), sums.end());
  d.queue.enqueueWriteBuffer(buffer, CL_TRUE, 0, raw.size() * sizeof(Acc), raw.data());
}

// The rows of the larger of the two sampling kernels, which share a launch shape.
int largestPixelRows(const Scene& scene, const SamplerConfig& config) {
  return std::max(samplePixelRows(scene, config), samplePixelRows(scene, plainConfig(config)));
}

// A frame's axis as kernels/sample.cl reads it (frameOfRows): x, y, z.
void writeVec3(const kern::MaVec3& v, float* w) {
  w[0] = v.x;
  w[1] = v.y;
  w[2] = v.z;
}

}  // namespace

std::string sampleKernelOptions(const Scene& scene, const SamplerConfig& config, int localSize, int pixelLanes,
                                int groupPixels) {
  const EnvmapTables& t = stageTables(scene, keepsStatistics(config));
  return fmt::format(
      "-cl-std=CL1.2 -DMA_TECHNIQUES={} -DMA_SPLIT_BRDF={} -DMA_USE_CDF={} -DMA_CDF_STEPS_ROW={} "
      "-DMA_CDF_STEPS_COL={} -DMA_ANALYTIC_RADIANCE={} -DMA_BANK_SHARES={} "
      "-DMA_ONE_SAMPLE={} -DMA_COUNT_INDEPENDENT={} -DMA_RIS_CANDIDATES={} -DMA_STATS={} -DMA_STORE_SAMPLES={} "
      "-DMA_SHARE_COLUMNS={} -DMA_OPTIMAL_WEIGHTS={} -DMA_PRODUCT_TABLES={} -DMA_PRODUCT_BLOCK_LOG2={} "
      "-DMA_PRODUCT_PLAIN_TEXELS={} -DMA_PRODUCT_CELLS={} -DMA_PIXEL_CELLS={} -DMA_PIXEL_CDF_STEPS={} "
      "-DMA_LOCAL_SIZE={} -DMA_PIXEL_LANES={} -DMA_GROUP_PIXELS={} "
      "-DMA_SPLIT_LOAD64={}",
      scene.techniqueCount(), scene.options.splitBrdf ? 1 : 0, t.useCdf ? 1 : 0, t.cdfStepsRow, t.cdfStepsCol,
      scene.envmap.coskExponent >= 0 ? 1 : 0, t.bankShares, config.estimator == Estimator::OneSample ? 1 : 0,
      config.estimator == Estimator::CountIndependent ? 1 : 0, config.risCandidates, config.statsMask,
      config.sampleCapacity > 0 ? 1 : 0, sampleColumns(scene, config).shareColumns, config.optimalWeights ? 1 : 0,
      scene.productTables.tables, scene.productTables.blockLog2, scene.productTables.plainTexels ? 1 : 0,
      scene.productTables.pixelCells ? 1 : 0, t.pixelCells, t.pixelCdfSteps, localSize, pixelLanes, groupPixels,
      pixelLanes > 0 ? 1 : 0);
}

int samplePixelLanes(const Scene& scene, const SamplerConfig& config, int deviceLanes) {
  return scene.tables.useCdf || config.risCandidates > 0 ? 0 : deviceLanes;
}

int samplePixelRows(const Scene& scene, const SamplerConfig& config) {
  return kern::pixelRowCount(config.optimalWeights, scene.techniqueCount(), scene.productTables.tables > 0,
                             stageTables(scene, keepsStatistics(config)).pixelCells, scene.productTables.pixelCells,
                             sampleColumns(scene, config).shareColumns > 0);
}

int pixelStageGroupPixels(const Scene& scene, const SamplerConfig& config, int lanes, uint64_t localMemBytes) {
  const int rows = largestPixelRows(scene, config);
  int pixels = lanes;
  while (pixels > 0 && pixelStageLocalBytes(lanes, pixels, rows) > localMemBytes) pixels /= 2;
  return pixels;
}

SceneBuffers::SceneBuffers(const Device& device, const Scene& scene, bool withPilot) : context_(device.context()) {
  const EnvmapTables& t = scene.tables;
  auto uploadTables = [&](const EnvmapTables& tables) {
    return Envmap{upload(device, tables.texels), upload(device, tables.cdfTable), upload(device, tables.aliasTable),
                  upload(device, tables.blockProbs)};
  };
  envmap_ = uploadTables(t);
  const EnvmapTables& pilot = stageTables(scene, true);
  if (&pilot == &t)
    pilotEnvmap_ = envmap_;
  else if (withPilot)
    pilotEnvmap_ = uploadTables(pilot);
  productFloats = upload(device, scene.productTables.floats);
  productWords = upload(device, scene.productTables.words);
  // The kernel's shading point rows (kernels/pixel_layout.h), from the reference's.
  std::vector<float> words(size_t(kern::shadingPointOffset(scene.pixelCount())));
  for (int p = 0; p < scene.pixelCount(); ++p) {
    const kern::ShadingPoint sp = makeShadingPoint(scene, p);
    float* w = words.data() + kern::shadingPointOffset(p);
    w[kern::ROW_RHO_D] = sp.brdf.rhoD;
    w[kern::ROW_RHO_S] = sp.brdf.rhoS;
    w[kern::ROW_N] = sp.brdf.n;
    w[kern::ROW_BRDF_BIN] = t.hasBank() ? float(t.brdfBinOfPixel[size_t(p)]) : 0.0f;
    writeVec3(sp.normalFrame.z, w + kern::ROW_NORMAL_X);
    writeVec3(sp.mirrorFrame.z, w + kern::ROW_MIRROR_X);
  }
  shadingPoints = upload(device, words);
}

const SceneBuffers::Envmap& SceneBuffers::envmap(bool keepsStatistics) const {
  if (!keepsStatistics) return envmap_;
  if (pilotEnvmap_.texels() == nullptr) throw std::logic_error("scene buffers made without the pilot's tables");
  return pilotEnvmap_;
}

Sampler::Sampler(const Device& device, const Scene& scene, const SamplerConfig& config, int localSize,
                 std::shared_ptr<const SceneBuffers> sceneBuffers)
    : StageSampler(scene, config), device_(device) {
  doubleSums_ = device.device.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
  // sampleStage runs at one size with and without running sums: that of the larger.
  const DeviceLimits limits = deviceLimits(device.device);
  const LaunchShape shape = chooseLocalSize(
      limits,
      [&](int size) { return sampleKernelLocalBytes(size, statSlots(), doubleSums_, largestPixelRows(scene, config)); },
      localSize);
  localSize_ = shape.localSize;
  pixelLanes_ = samplePixelLanes(scene, config, limits.pixelLanes);
  groupPixels_ = pixelLanes_ > 0 ? pixelStageGroupPixels(scene, config, pixelLanes_, limits.localMemBytes) : 0;
  if (groupPixels_ == 0) pixelLanes_ = 0;
  // Stored samples need no running sums: exact's pilot runs samplePixelStage too.
  statisticsLanes_ = config.statsMask == 0 ? pixelLanes_ : 0;
  share_.launch = shape.why;
  if (pixelLanes_ > 0)
    share_.launch += fmt::format("; stages without running sums: {} pixels a work-group, each across its {} lanes",
                                 groupPixels_, pixelLanes_);
  const std::string plainOptions =
                        sampleKernelOptions(scene, plainConfig(config), localSize_, pixelLanes_, groupPixels_),
                    statisticsOptions = sampleKernelOptions(scene, config, localSize_, statisticsLanes_,
                                                            statisticsLanes_ > 0 ? groupPixels_ : 0);
  auto kernelFor = [](int lanes) { return lanes > 0 ? "samplePixelStage" : "sampleStage"; };
  plainKernel_ = cl::Kernel(buildProgram(device, "sample.cl", plainOptions), kernelFor(pixelLanes_));
  kernel_ = keepsStatistics(config)
                ? cl::Kernel(buildProgram(device, "sample.cl", statisticsOptions), kernelFor(statisticsLanes_))
                : plainKernel_;
  launchIdentity_ = fmt::format("{}, driver {}, {} compute units; kernel sources {:016x}; {}; {}", device.name(),
                                device.device.getInfo<CL_DRIVER_VERSION>(),
                                device.device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>(), embeddedSourcesHash(),
                                plainOptions, keepsStatistics(config) ? statisticsOptions : "no statistics kernel");
  if (!sceneBuffers) sceneBuffers = std::make_shared<SceneBuffers>(device, scene, keepsStatistics(config));
  if (sceneBuffers->context() != device.context()) throw std::logic_error("scene buffers of another context");
  sceneBuffers_ = std::move(sceneBuffers);
  // OpenCL buffers cannot be empty: a method without running sums or stored samples
  // gets a one-element placeholder.
  const size_t accSize = doubleSums_ ? sizeof(double) : sizeof(float);
  const size_t slots = std::max<size_t>(1, size_t(scene.pixelCount()) * statSlots());
  stats_ = cl::Buffer(device.context, CL_MEM_READ_WRITE, slots * accSize);
  device.queue.enqueueFillBuffer(stats_, cl_uchar(0), 0, slots * accSize);
  // The stored samples, then the spare record that the kernel's lanes store a sample they
  // do not keep into (kernels/stats.h, spareSampleIndex), copied once. (Written in place,
  // through a map, in memory the buffer uses or by a kernel, they saved the copy, but the
  // render then took 0.02–0.05 s more host time: docs/results.md, "Stored samples sized
  // by the scene's techniques".)
  samples_ = config.sampleCapacity > 0 ? upload(device, emptyStoredSamples(scene, config, 1), CL_MEM_READ_WRITE)
                                       : cl::Buffer(device.context, CL_MEM_READ_WRITE, sizeof(float));
  // Each buffer's size is the offset of the pixel past the last (kernels/pixel_layout.h).
  const int pixels = scene.pixelCount(), M = scene.techniqueCount();
  counts_ = cl::Buffer(device.context, CL_MEM_READ_ONLY, size_t(kern::countsOffset(pixels, M)) * sizeof(int32_t));
  firstIndex_ = cl::Buffer(device.context, CL_MEM_READ_ONLY, size_t(kern::countsOffset(pixels, M)) * sizeof(uint32_t));
  pixelOrder_ = cl::Buffer(device.context, CL_MEM_READ_ONLY, size_t(pixels) * sizeof(int32_t));
  rgb_ = cl::Buffer(device.context, CL_MEM_WRITE_ONLY, size_t(kern::estimateOffset(pixels)) * accSize);
  moments_ = cl::Buffer(device.context, CL_MEM_WRITE_ONLY, size_t(kern::momentsOffset(pixels, M)) * accSize);
  if (config.optimalWeights)
    coefficients_ =
        cl::Buffer(device.context, CL_MEM_READ_ONLY, size_t(kern::coefficientsOffset(pixels, M)) * sizeof(float));
  share_.name = device.name();
  // PoCL compiles a kernel for its work-group size at the first launch, and its threads
  // take their first work-groups: pay that here, with every pixel and no samples (a
  // stage's own order would launch none), not inside the first timed stage.
  StagePlan empty;
  empty.techniqueCount = scene.techniqueCount();
  empty.counts.assign(size_t(scene.pixelCount()) * empty.techniqueCount, 0);
  empty.firstIndex.assign(empty.counts.size(), 0u);
  std::vector<int32_t> everyPixel(static_cast<size_t>(pixels));
  std::iota(everyPixel.begin(), everyPixel.end(), 0);
  runOrder(empty, 0, 0, {0, pixels}, everyPixel);
  if (keepsStatistics(config)) {
    empty.keepStatistics = false;
    runOrder(empty, 0, 0, {0, pixels}, everyPixel);
  }
  reset();
}

StageResult Sampler::runPixels(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range) {
  return runOrder(
      plan, seed, firstSlot, range,
      pixelLanes(storesStatistics(plan)) > 0 ? sampledPixels(plan, range) : coherentPixelOrder(plan, range));
}

StageResult Sampler::runOrder(const StagePlan& plan, uint64_t seed, int firstSlot, PixelRange range,
                              const std::vector<int32_t>& order) {
  const int M = scene_.techniqueCount();
  StageResult result;
  if (range.size() == 0) return result;
  // With the counts of the three pixels each side of the range, where a pair or quad
  // across its edge reads the others' (kernels/pixel_pairs.h): a tile of 16 pixels need
  // not start a row.
  const PixelRange written{std::max(0, range.begin - 3), std::min(scene_.pixelCount(), range.end + 3)};
  const size_t rows = kern::countsOffset(written.size(), M), firstRow = kern::countsOffset(written.begin, M);
  const cl::CommandQueue& queue = device_.queue;
  queue.enqueueWriteBuffer(counts_, CL_FALSE, firstRow * sizeof(int32_t), rows * sizeof(int32_t),
                           plan.counts.data() + firstRow);
  queue.enqueueWriteBuffer(firstIndex_, CL_FALSE, firstRow * sizeof(uint32_t), rows * sizeof(uint32_t),
                           plan.firstIndex.data() + firstRow);
  if (!order.empty()) queue.enqueueWriteBuffer(pixelOrder_, CL_FALSE, 0, order.size() * sizeof(int32_t), order.data());
  const bool statistics = storesStatistics(plan);
  cl::Kernel& kernel = statistics ? kernel_ : plainKernel_;
  const SceneBuffers& b = *sceneBuffers_;
  const SceneBuffers::Envmap& env = b.envmap(statistics);
  if (config_.optimalWeights) writeCoefficients(plan, range);
  // The optimal weights' coefficients are an argument of their kernels only.
  auto bind = [&](const auto&... args) {
    if (config_.optimalWeights)
      bindKernelArgs(kernel, args..., coefficients_);
    else
      bindKernelArgs(kernel, args...);
  };
  bind(env.texels, env.cdfTable, env.aliasTable, env.blockProbs, b.productFloats, b.productWords,
       cl_int(scene_.tables.width), cl_int(scene_.tables.height), cl_float(scene_.envmap.coskExponent),
       cl_int(stageTables(scene_, statistics).blockLog2), b.shadingPoints, counts_, firstIndex_,
       cl_int(plan.stageSamples), cl_uint(seed & 0xffffffffu), cl_uint(seed >> 32), cl_int(scene_.firstPixel),
       cl_int(order.size()), cl_int(scene_.grid.width), pixelOrder_, rgb_, moments_, stats_, samples_,
       cl_int(firstSlot), cl_int(config_.sampleCapacity), cl_int(storedSampleCount()));
  const int lanes = pixelLanes(statistics);
  const size_t local = lanes > 0 ? size_t(lanes) : size_t(localSize_);
  const size_t groups = lanes > 0 ? (order.size() + size_t(groupPixels_) - 1) / size_t(groupPixels_) : 0;
  const size_t global = lanes > 0 ? groups * local : (order.size() + local - 1) / local * local;
  if (global > 0) {
    cl::Event done;
    queue.enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(global), cl::NDRange(local), nullptr, &done);
    done.wait();
    result.kernelSeconds = eventSeconds(done);
  }
  auto read = [&](const cl::Buffer& b, size_t first, size_t n) {
    return doubleSums_ ? readSums<double>(device_, b, first, n) : readSums<float>(device_, b, first, n);
  };
  result.rgb = read(rgb_, kern::estimateOffset(range.begin), kern::estimateOffset(range.size()));
  result.moments = read(moments_, kern::momentsOffset(range.begin, M), kern::momentsOffset(range.size(), M));
  // The pixels left out of the launch took no samples: their sums are zero, whatever
  // the buffers hold from earlier stages.
  if (order.size() < size_t(range.size()))
    for (int p = range.begin; p < range.end; ++p)
      if (!takesSamples(plan, p)) {
        const size_t i = size_t(p - range.begin);
        std::fill_n(result.rgb.begin() + ptrdiff_t(kern::estimateOffset(int(i))), 3, 0.0);
        std::fill_n(result.moments.begin() + ptrdiff_t(kern::momentsOffset(int(i), M)), 2 * M, 0.0);
      }
  share_.pixelStages += range.size();
  share_.samples += (long long)range.size() * plan.stageSamples;
  share_.tiles += 1;
  share_.kernelSeconds += result.kernelSeconds;
  return result;
}

std::vector<double> Sampler::statistics() {
  const size_t n = size_t(scene_.pixelCount()) * statSlots();
  if (n == 0) return {};
  return doubleSums_ ? readSums<double>(device_, stats_, 0, n) : readSums<float>(device_, stats_, 0, n);
}

void Sampler::loadStatistics(const std::vector<double>& stats) {
  if (stats.size() != size_t(scene_.pixelCount()) * statSlots())
    throw std::logic_error("statistics of another sampler");
  if (stats.empty()) return;
  doubleSums_ ? writeSums<double>(device_, stats_, stats) : writeSums<float>(device_, stats_, stats);
}

void Sampler::loadStoredSamples(const std::vector<float>& samples) {
  if (samples.size() != storedSampleCount()) throw std::logic_error("stored samples of another sampler");
  if (!samples.empty())
    device_.queue.enqueueWriteBuffer(samples_, CL_TRUE, 0, samples.size() * sizeof(float), samples.data());
}

std::vector<DeviceShare> Sampler::deviceShares() const { return {share_}; }

void Sampler::writeCoefficients(const StagePlan& plan, PixelRange range) {
  const int M = scene_.techniqueCount();
  const size_t first = kern::coefficientsOffset(range.begin, M), values = kern::coefficientsOffset(range.size(), M);
  const std::vector<float> zeros(plan.optimalCoefficients.empty() ? values : 0, 0.0f);
  const float* rows = zeros.empty() ? plan.optimalCoefficients.data() + first : zeros.data();
  device_.queue.enqueueWriteBuffer(coefficients_, CL_TRUE, first * sizeof(float), values * sizeof(float), rows);
}

void Sampler::forgetStages() {
  const size_t bytes = size_t(scene_.pixelCount()) * statSlots() * (doubleSums_ ? sizeof(double) : sizeof(float));
  if (bytes > 0) device_.queue.enqueueFillBuffer(stats_, cl_uchar(0), 0, bytes);
  share_ = share_.restarted();
}

std::vector<float> Sampler::storedSamples() {
  std::vector<float> out(storedSampleCount());
  if (!out.empty()) device_.queue.enqueueReadBuffer(samples_, CL_TRUE, 0, out.size() * sizeof(float), out.data());
  return out;
}

}  // namespace misalloc
