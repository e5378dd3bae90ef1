#include "render/Sampler.h"

#include <fmt/format.h>

#include <chrono>

#include "Error.h"

namespace misalloc {
namespace {

template <typename T>
cl::Buffer upload(const Device& d, const std::vector<T>& data) {
  return cl::Buffer(d.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, data.size() * sizeof(T),
                    const_cast<T*>(data.data()));
}

template <typename Acc>
std::vector<double> readSums(const Device& d, const cl::Buffer& buffer, size_t count) {
  std::vector<Acc> raw(count);
  d.queue.enqueueReadBuffer(buffer, CL_TRUE, 0, count * sizeof(Acc), raw.data());
  return std::vector<double>(raw.begin(), raw.end());
}

}  // namespace

std::string sampleKernelOptions(const Scene& scene, Estimator estimator, int localSize) {
  const EnvmapTables& t = scene.tables;
  return fmt::format(
      "-cl-std=CL1.2 -DMA_TECHNIQUES={} -DMA_SPLIT_BRDF={} -DMA_USE_CDF={} -DMA_CDF_STEPS_ROW={} "
      "-DMA_CDF_STEPS_COL={} -DMA_COSK=((float)({:.9g})) -DMA_ONE_SAMPLE={} -DMA_LOCAL_SIZE={}",
      scene.techniqueCount(), scene.options.splitBrdf ? 1 : 0, t.useCdf ? 1 : 0, t.cdfStepsRow, t.cdfStepsCol,
      scene.envmap.coskExponent, estimator == Estimator::OneSample ? 1 : 0, localSize);
}

Sampler::Sampler(const Device& device, const Scene& scene, Estimator estimator, int localSize)
    : device_(device), scene_(scene), localSize_(localSize) {
  if (localSize < 1) throw InputError("--local-size must be at least 1");
  doubleSums_ = device.device.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
  cl::Program program = buildProgram(device, "sample.cl", sampleKernelOptions(scene, estimator, localSize));
  kernel_ = cl::Kernel(program, "sampleStage");
  const EnvmapTables& t = scene.tables;
  texels_ = upload(device, t.texels);
  samplerTable_ = upload(device, t.samplerTable);
  aliasIndex_ = upload(device, t.aliasIndex);
  std::vector<float> params;
  params.reserve(scene.grid.pixels.size() * 4);
  for (const auto& p : scene.grid.pixels) params.insert(params.end(), {p.rhoD, p.rhoS, p.n, 0.0f});
  brdfParams_ = upload(device, params);
}

StageResult Sampler::run(const StagePlan& plan, uint64_t seed) {
  const int pixels = scene_.pixelCount(), M = scene_.techniqueCount();
  if (plan.techniqueCount != M || plan.counts.size() != size_t(pixels) * M)
    throw std::logic_error("stage plan does not match the scene");
  const size_t accSize = doubleSums_ ? sizeof(double) : sizeof(float);
  cl::Buffer counts = upload(device_, plan.counts), firstIndex = upload(device_, plan.firstIndex);
  cl::Buffer rgb(device_.context, CL_MEM_WRITE_ONLY, size_t(pixels) * 3 * accSize);
  cl::Buffer moments(device_.context, CL_MEM_WRITE_ONLY, size_t(pixels) * M * 2 * accSize);
  int a = 0;
  kernel_.setArg(a++, texels_);
  kernel_.setArg(a++, samplerTable_);
  kernel_.setArg(a++, aliasIndex_);
  kernel_.setArg(a++, cl_int(scene_.tables.width));
  kernel_.setArg(a++, cl_int(scene_.tables.height));
  kernel_.setArg(a++, brdfParams_);
  for (float m : scene_.mirror) kernel_.setArg(a++, m);
  kernel_.setArg(a++, counts);
  kernel_.setArg(a++, firstIndex);
  kernel_.setArg(a++, cl_int(plan.stageSamples));
  kernel_.setArg(a++, cl_uint(seed & 0xffffffffu));
  kernel_.setArg(a++, cl_uint(seed >> 32));
  kernel_.setArg(a++, cl_int(pixels));
  kernel_.setArg(a++, rgb);
  kernel_.setArg(a++, moments);
  size_t global = (size_t(pixels) + localSize_ - 1) / localSize_ * localSize_;
  cl::Event done;
  device_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange(global), cl::NDRange(localSize_), nullptr,
                                     &done);
  done.wait();
  StageResult result;
  result.kernelSeconds =
      double(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() - done.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
      1e-9;
  if (doubleSums_) {
    result.rgb = readSums<double>(device_, rgb, size_t(pixels) * 3);
    result.moments = readSums<double>(device_, moments, size_t(pixels) * M * 2);
  } else {
    result.rgb = readSums<float>(device_, rgb, size_t(pixels) * 3);
    result.moments = readSums<float>(device_, moments, size_t(pixels) * M * 2);
  }
  return result;
}

}  // namespace misalloc
