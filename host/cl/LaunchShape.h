#pragma once
// The work-group size of the sampling kernel (kernels/sample.cl) on a given device:
// PoCL's CPU device vectorises best at 8 work-items (docs/pocl.md, rule 4), a GPU wants
// 64–256, and sampleStage's local memory grows with the work-group and the running sums.
#include <CL/opencl.hpp>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace misalloc {

// What a device allows a work-group.
struct DeviceLimits {
  bool cpu = false;
  size_t maxWorkGroupSize = 0;  // CL_DEVICE_MAX_WORK_GROUP_SIZE
  uint64_t localMemBytes = 0;   // CL_DEVICE_LOCAL_MEM_SIZE
  // Work-items that run in lockstep (a warp, a wavefront): a work-group of a multiple of
  // it leaves no lane idle. 1 where it does not matter (CPU).
  size_t preferredMultiple = 1;
  // CPU: its native float vector width (CL_DEVICE_NATIVE_VECTOR_WIDTH_FLOAT), rounded
  // down to a power of two and at most kMaxPixelLanes: the lanes of samplePixelStage,
  // which samples one pixel at a time across them.
  // 0 on other devices, which run sampleStage for every stage.
  int pixelLanes = 0;
};

// samplePixelStage runs each technique's n_k in whole passes of its lanes, so a pass of
// 16 (AVX-512's float width) leaves up to 15 lanes idle per technique and pixel, and
// exact's pilot of 8 per technique half of them. On an AVX-512 Zen 5, 8 lanes rendered
// the same images 1.03–1.12× faster than 16 (docs/results.md, "Eight lanes on
// AVX-512").
inline constexpr int kMaxPixelLanes = 8;

// A GPU's preferred multiple is its warp (cl_nv_device_attribute_query) or wavefront
// (cl_amd_device_attribute_query) width where the device reports it, else 32: the
// kernel-free OpenCL 1.2 queries say nothing about it.
DeviceLimits deviceLimits(const cl::Device& device);

// The local memory of sampleStage at this work-group size: its sums and running sums
// (`statSlots`, StageStatistics::statSlots()), in double where `doubleSums` (ma_acc,
// kernels/common.h) else float, and per work-item its pixel's rows (`pixelRows`,
// kern::pixelRowCount) and pass count. With no running sums the kernel declares a
// one-row placeholder that it never touches: PoCL and clang's nvptx64 back end both
// drop it, so it is not counted.
size_t sampleKernelLocalBytes(int localSize, int statSlots, bool doubleSums, int pixelRows);

// The local memory of samplePixelStage at `lanes` lanes and `pixels` pixels a
// work-group, at most: each pixel's rows in a power-of-two block (kern::pixelRowBlock),
// the sampled pixel's inputs for the sample loop, its chunk of sample terms and its
// sums (kernels/sample.cl).
size_t pixelStageLocalBytes(int lanes, int pixels, int pixelRows);

struct LaunchShape {
  int localSize = 0;
  std::string why;  // one line for the report
};

// CPU: 8. Otherwise the largest of 256, 128, 64, 32 that is a multiple of
// preferredMultiple, at most maxWorkGroupSize and whose localBytes(size) fit
// localMemBytes; failing all of them, the largest smaller power of two that fits.
// overrideLocalSize > 0 (--local-size) is taken as given if it fits the limits.
// Throws DeviceError for an override that does not fit this device (exit code 3, as
// every limit of a device an option exceeds), naming --local-size, the limit and the
// bytes it needs, and if not even one work-item fits.
LaunchShape chooseLocalSize(const DeviceLimits& limits, const std::function<size_t(int)>& localBytes,
                            int overrideLocalSize = 0);

}  // namespace misalloc
