#include "sampling/CostModel.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "Error.h"
#include "NumberList.h"
#include "sampling/StageSampler.h"

namespace misalloc {

namespace {

// Least squares on the relative error, (T̂ − T)/T, so that short launches weigh as much
// as long ones, over the unknowns `free` of x = (t_0, c_0, …, c_{M−1}), none negative:
// an unknown that comes out negative leaves the fit (t_0 first, which noise on launches
// of few samples drives below zero) and the rest are fitted again.
Eigen::VectorXd nonNegativeFit(const Eigen::MatrixXd& a, std::vector<int> free) {
  const int n = int(a.rows());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(a.cols());
  while (!free.empty()) {
    Eigen::MatrixXd sub(n, int(free.size()));
    for (size_t j = 0; j < free.size(); ++j) sub.col(int(j)) = a.col(free[j]);
    const Eigen::VectorXd solution = sub.colPivHouseholderQr().solve(Eigen::VectorXd::Ones(n));
    x.setZero();
    for (size_t j = 0; j < free.size(); ++j) x(free[j]) = solution(int(j));
    // t_0 leaves when negative, else the least c_k when it is not positive.
    const bool interceptFree = free.front() == 0;
    auto leaving = interceptFree && x(0) < 0 ? free.begin()
                                             : std::min_element(free.begin() + (interceptFree ? 1 : 0), free.end(),
                                                                [&](int i, int j) { return x(i) < x(j); });
    if (leaving == free.end() || (*leaving != 0 && x(*leaving) > 0)) break;
    x(*leaving) = 0;
    free.erase(leaving);
  }
  return x;
}

}  // namespace

const char* costSourceName(CostSource source) {
  switch (source) {
    case CostSource::Given:
      return "--cost";
    case CostSource::Calibrated:
      return "calibrated";
    case CostSource::Cached:
      return "cache";
  }
  throw std::logic_error("unknown cost source");
}

CostModel CostModel::given(std::vector<double> costs) {
  CostModel model(int(costs.size()));
  for (Kernel& k : model.kernels_) k.costs.perSample = costs;
  model.source_ = CostSource::Given;
  return model;
}

CostModel CostModel::cached(KernelCosts plain, KernelCosts withStatistics) {
  CostModel model(int(plain.perSample.size()));
  model.kernels_[0].costs = std::move(plain);
  model.kernels_[1].costs = std::move(withStatistics);
  model.source_ = CostSource::Cached;
  return model;
}

CostModel::CostModel(int techniqueCount) {
  for (Kernel& k : kernels_) k.costs.perSample.assign(techniqueCount, 0.0);
}

void CostModel::observe(const LaunchWork& work, double seconds) {
  if (source_ != CostSource::Calibrated || !(seconds > 0)) return;
  Kernel& k = kernels_[work.keepsStatistics ? 1 : 0];
  k.seen.push_back({work.slots, seconds});
  fit(k);
}

double CostModel::predict(const LaunchWork& work) const {
  const KernelCosts& k = kernel(work.keepsStatistics).costs;
  double seconds = k.perLaunch;
  for (size_t i = 0; i < work.slots.size(); ++i) seconds += k.perSample[i] * work.slots[i];
  return seconds;
}

void CostModel::fit(Kernel& kernel) {
  const int M = int(kernel.costs.perSample.size()), unknowns = M + 1, n = int(kernel.seen.size());
  Eigen::MatrixXd a(n, unknowns);
  for (int i = 0; i < n; ++i) {
    const Launch& launch = kernel.seen[i];
    a(i, 0) = 1 / launch.seconds;
    for (int k = 0; k < M; ++k) a(i, 1 + k) = launch.slots[k] / launch.seconds;
  }
  std::vector<int> costs;
  for (int k = 0; k < M; ++k) costs.push_back(1 + k);
  std::vector<int> free = costs;
  if (n > M) free.insert(free.begin(), 0);  // t_0 only with a launch to spare
  Eigen::VectorXd x = nonNegativeFit(a, free);
  // Launches so short that t_0 explains their times, every c_k within the noise of 0
  // (a tiny image on a fast device): the samples then take all the time, or the
  // allocations would have no cost to weigh. Without t_0 some c_k > 0 wherever a launch
  // had samples.
  if ((x.tail(M).array() <= 0).all()) x = nonNegativeFit(a, costs);
  kernel.costs.perLaunch = x(0);
  kernel.costs.launches = n;
  // A technique whose samples the fit cannot tell from free (its time within the
  // noise of the others') costs what the cheapest measured one does: every cost > 0.
  double cheapest = 0;
  for (int k = 0; k < M; ++k)
    if (x(1 + k) > 0 && (cheapest == 0 || x(1 + k) < cheapest)) cheapest = x(1 + k);
  if (cheapest == 0) throw std::logic_error("cost model: no launch it was fitted on took a sample");
  for (int k = 0; k < M; ++k) kernel.costs.perSample[k] = x(1 + k) > 0 ? x(1 + k) : cheapest;
}

namespace {

StagePlan calibrationPlan(const Scene& scene, const std::vector<int>& counts, bool keepStatistics) {
  StagePlan plan;
  plan.techniqueCount = scene.techniqueCount();
  plan.keepStatistics = keepStatistics;
  for (int n : counts) plan.stageSamples += n;
  // The pixels a render's stages launch: a calibration that also sampled the background
  // fitted its fixed cost to pixels that renders leave out (LaunchWork.h).
  plan.counts = sameCountsEverywhere(scene.pixelCount(), counts);
  leaveOutBackground(scene, plan.counts);
  plan.firstIndex.assign(plan.counts.size(), 0u);
  return plan;
}

// Samples per technique that make each technique's samples in a launch of the covered
// pixels take about max(10 ms, the launch's fixed time), the most that `capacity`
// allows, from launches of 1 and kProbe samples per technique. Sized by the whole
// launch instead, the shapes took 1 and 4 samples: on a CPU one pass of its lanes
// each, the same work, and where the fixed time dominates (the optimal pdf per pixel
// builds every pixel's table in each launch) the fitted costs were its noise. One
// cached calibration priced the BRDF technique's samples 8x below the envmap's, against
// 1.5–1.8x measured again, and `exact` on its scene chose from it an allocation with
// 2x `equal`'s error (docs/results.md).
int calibrationSize(StageSampler& sampler, bool keepStatistics, int capacity) {
  const Scene& scene = sampler.scene();
  const int M = scene.techniqueCount();
  // Past the first passes of a CPU's lanes (kMaxPixelLanes), whose launches grow by
  // whole passes.
  constexpr int kProbe = 33;
  const int probe = std::clamp(capacity, 1, kProbe);
  const StagePlan one = calibrationPlan(scene, std::vector<int>(M, 1), keepStatistics),
                  more = calibrationPlan(scene, std::vector<int>(M, probe), keepStatistics);
  // The faster of two launches, after one not timed (a fresh process's first launches
  // are slow, calibrateCostModel).
  auto seconds = [&](const StagePlan& plan) {
    double fastest = std::numeric_limits<double>::infinity();
    for (int round = 0; round < 2; ++round) {
      sampler.reset();
      fastest = std::min(fastest, sampler.run(plan, 0).kernelSeconds);
    }
    return fastest;
  };
  auto slots = [&](const StagePlan& plan) {
    const std::vector<double> s = sampler.launchWork(plan).slots;
    return std::accumulate(s.begin(), s.end(), 0.0);
  };
  const double oneSlots = slots(one), moreSlots = slots(more);
  if (moreSlots == 0) return 1;  // no covered pixel: nothing to size
  sampler.reset();
  sampler.run(one, 0);
  const double oneSeconds = seconds(one), moreSeconds = seconds(more);
  // At least an eighth of the time per slot of the launch of `probe` samples: noise on
  // launches that hardly differ would otherwise size the shapes to minutes.
  const double perSlot = std::max(moreSlots > oneSlots ? (moreSeconds - oneSeconds) / (moreSlots - oneSlots) : 0.0,
                                  std::max(moreSeconds, 1e-9) / (8 * moreSlots));
  const double fixed = std::max(oneSeconds - oneSlots * perSlot, 0.0);
  const double perSample = perSlot * moreSlots / (probe * M);  // one technique's, on every covered pixel
  constexpr double kLaunchSeconds = 0.01;
  return std::clamp(int(std::lround(std::max(kLaunchSeconds, fixed) / perSample)), 1, std::max(1, capacity / 4));
}

}  // namespace

CostModel calibrateCostModel(StageSampler& sampler) {
  const Scene& scene = sampler.scene();
  const int M = scene.techniqueCount();
  const bool withStatistics = keepsStatistics(sampler.config());
  std::vector<StagePlan> shapes;
  for (bool statistics : {false, true}) {
    if (statistics && !withStatistics) continue;
    // Samples per technique a launch may take: a stage that keeps statistics stores
    // its samples, and its shapes fit in the slots.
    const int slots = statistics && sampler.config().sampleCapacity > 0 ? sampler.config().sampleCapacity
                                                                        : std::numeric_limits<int>::max() / 8;
    const int capacity = slots / M;
    const int size = calibrationSize(sampler, statistics, capacity);
    // Each technique alone at two sizes, where the stored samples' slots allow.
    const int large = std::min(4 * size, capacity);
    for (int k = 0; k < M; ++k)
      for (int n : {size, large}) {
        if (n == large && large == size) continue;
        std::vector<int> counts(M, 0);
        counts[k] = n;
        shapes.push_back(calibrationPlan(scene, counts, statistics));
      }
    shapes.push_back(calibrationPlan(scene, std::vector<int>(M, size), statistics));
  }
  // A round that is not timed first: a fresh process's first launches ran up to twice
  // as long per sample as its later ones (the tables' pages and caches not yet warm),
  // and a model fitted on them overestimated every stage after.
  constexpr int kRounds = 3;
  std::vector<std::vector<double>> seconds(shapes.size());
  for (int round = -1; round < kRounds; ++round)
    for (size_t s = 0; s < shapes.size(); ++s) {
      sampler.reset();
      const double launch = sampler.run(shapes[s], uint64_t(round + 1)).kernelSeconds;
      if (round >= 0) seconds[s].push_back(launch);
    }
  sampler.reset();
  CostModel model(M);
  for (size_t s = 0; s < shapes.size(); ++s) {
    // The median round of each shape, which a round slowed by another process does not move.
    std::nth_element(seconds[s].begin(), seconds[s].begin() + kRounds / 2, seconds[s].end());
    model.observe(sampler.launchWork(shapes[s]), seconds[s][kRounds / 2]);
  }
  return model;
}

std::vector<double> parseCosts(const std::string& list, int techniqueCount) {
  std::vector<double> costs = parseNumberList("--cost", list, list, size_t(techniqueCount), "one cost per technique");
  for (double c : costs)
    if (c <= 0) throw InputError(fmt::format("--cost {}: costs must be positive, got {}", list, c));
  return costs;
}

}  // namespace misalloc
