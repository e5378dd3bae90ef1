#pragma once
// The time of a sampling launch, predicted from the work it does (LaunchWork.h):
//
//   T = t_0 + Σ_k c_k · S_k,
//
// S_k technique k's sample slots as the kernel runs them (per work-group maxima), t_0
// what a launch costs whatever its samples (the pixels' loads and stores, the launch).
// The kernel with running sums and stored samples and the one without have a set of
// (t_0, c_k) each. The allocations weigh a technique by its c_k, of the kernel that
// runs the stage they allocate. A model is fixed once made: a render's stages are
// predicted by it but do not refit it, so that its allocations depend on its seed and
// its model only (render/CostCache.h keeps a model per device, kernel build and scene).
#include <string>
#include <vector>

#include "sampling/LaunchWork.h"

namespace misalloc {

class StageSampler;

// Where a model's costs came from.
enum class CostSource {
  Given,       // --cost
  Calibrated,  // calibrateCostModel, in this process
  Cached,      // a calibration read from the cost cache (render/CostCache.h)
};

// "--cost", "calibrated", "cache": the reports' costs_source.
const char* costSourceName(CostSource source);

class CostModel {
 public:
  // One kernel's fitted (t_0, c_k), and the launches they were fitted on.
  struct KernelCosts {
    double perLaunch = 0;
    std::vector<double> perSample;
    int launches = 0;
  };

  // Costs as given (--cost): c_k for both kernels, t_0 = 0; observations change nothing.
  static CostModel given(std::vector<double> costs);
  // A fit made before (the cost cache's): the kernel without statistics, then the one with.
  static CostModel cached(KernelCosts plain, KernelCosts withStatistics);
  // No launch seen yet: observe() before predict().
  explicit CostModel(int techniqueCount);

  // Adds a launch that took `seconds` and fits again: least squares on the relative
  // error over every launch of the same kernel seen so far. For calibrateCostModel.
  void observe(const LaunchWork& work, double seconds);
  double predict(const LaunchWork& work) const;
  // c_k per sample of the kernel with or without statistics, each > 0.
  const std::vector<double>& perSample(bool keepsStatistics) const { return kernel(keepsStatistics).costs.perSample; }
  double perLaunch(bool keepsStatistics) const { return kernel(keepsStatistics).costs.perLaunch; }
  // The launches the fit of that kernel has seen.
  int launchCount(bool keepsStatistics) const { return kernel(keepsStatistics).costs.launches; }
  KernelCosts kernelCosts(bool keepsStatistics) const { return kernel(keepsStatistics).costs; }
  bool isGiven() const { return source_ == CostSource::Given; }
  CostSource source() const { return source_; }

 private:
  struct Launch {
    std::vector<double> slots;
    double seconds;
  };
  struct Kernel {
    KernelCosts costs;
    std::vector<Launch> seen;
  };
  const Kernel& kernel(bool keepsStatistics) const { return kernels_[keepsStatistics ? 1 : 0]; }
  static void fit(Kernel& kernel);

  Kernel kernels_[2];
  CostSource source_ = CostSource::Calibrated;
};

// A model of `sampler`'s launches from calibration launches of a few shapes on every
// pixel (each technique alone at two sizes, all together), interleaved over rounds so
// that a drift of the machine's speed reaches every shape alike, on each kernel the
// sampler has, sized so that each technique's samples outweigh the launch's fixed time.
// They take 1.5–4.5 s on a 256×256 image on two cores; the sampler is reset() afterwards.
CostModel calibrateCostModel(StageSampler& sampler);

// "--cost c1,c2[,c3]": one positive number per technique, else InputError.
std::vector<double> parseCosts(const std::string& list, int techniqueCount);

}  // namespace misalloc
