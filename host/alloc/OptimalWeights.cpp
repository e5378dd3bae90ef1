#include "alloc/OptimalWeights.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "Constants.h"
#include "KernelCode.h"
#include "alloc/Pooling.h"
#include "sampling/KernelViews.h"

namespace misalloc {
namespace {

// p_α(x) = Σ_k α_k p_k(x) ([HS14] eq. 4.2), in double: kernels/estimator.h's
// mixturePdf is the kernel's float one.
double mixtureDensity(const double* fractions, const double* pdfs, int techniqueCount) {
  double p = 0;
  for (int k = 0; k < techniqueCount; ++k) p += fractions[k] * pdfs[k];
  return p;
}

}  // namespace

OptimalWeightsSystem optimalWeightsSystem(const double* slots, unsigned mask, int techniqueCount) {
  if (!(mask & MA_STATS_OPTIMAL)) throw std::logic_error("optimal weights without their running sums");
  const int M = techniqueCount, perTechnique = MA_STATS_PER_TECHNIQUE(int(mask), M);
  // The optimal weights' sums close each technique's slots (kernels/stats.h).
  const int first = perTechnique - MA_OPTIMAL_SYSTEM_SUMS(M);
  OptimalWeightsSystem system{0, Eigen::MatrixXd::Zero(M, M), Eigen::MatrixXd::Zero(M, 3)};
  for (int t = 0; t < M; ++t) {
    const double* s = slots + t * perTechnique;
    system.samples += s[0];
    s += first;
    for (int row = 0; row < M; ++row)
      for (int col = row; col < M; ++col) system.A(row, col) += *s++;
    for (int ch = 0; ch < 3; ++ch)
      for (int k = 0; k < M; ++k) system.b(k, ch) += *s++;
  }
  system.A.triangularView<Eigen::StrictlyLower>() = system.A.transpose();
  if (system.samples > 0) {
    system.A /= system.samples;
    system.b /= system.samples;
  }
  return system;
}

double trustedEigenvalue(double samples, int techniqueCount) { return techniqueCount / std::sqrt(samples); }

PixelCoefficients solveOptimalWeights(const OptimalWeightsSystem& system) {
  const int M = int(system.A.rows());
  PixelCoefficients out{std::vector<double>(size_t(3) * M, 0.0), kWeightsSolved};
  if (!system.A.allFinite() || !system.b.allFinite() || !std::isfinite(system.samples)) {
    out.fallback = kWeightsNonFinite;
    return out;
  }
  if (system.samples < kMinSamplesPerTechnique * M) {
    out.fallback = kWeightsTooFewSamples;
    return out;
  }
  const Eigen::VectorXd diagonal = system.A.diagonal();
  if ((diagonal.array() <= 0).any()) {  // a technique whose pdf no sample reached
    out.fallback = kWeightsIllConditioned;
    return out;
  }
  const Eigen::VectorXd d = diagonal.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd S = d.asDiagonal() * system.A * d.asDiagonal();
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(S);
  if (eigen.info() != Eigen::Success || !(eigen.eigenvalues()(0) >= trustedEigenvalue(system.samples, M))) {
    out.fallback = kWeightsIllConditioned;
    return out;
  }
  // a_c = D S⁻¹ D b̃_c: [Kon19]'s A a = b, count-free (OptimalWeightsSystem).
  const Eigen::MatrixXd a =
      d.asDiagonal() *
      (eigen.eigenvectors() * eigen.eigenvalues().cwiseInverse().asDiagonal() * eigen.eigenvectors().transpose()) *
      d.asDiagonal() * system.b;
  if (!a.allFinite() || (a.array().abs() > double(FLT_MAX)).any()) {
    out.fallback = kWeightsNonFinite;
    return out;
  }
  for (int ch = 0; ch < 3; ++ch)
    for (int k = 0; k < M; ++k) out.a[size_t(ch) * M + k] = a(k, ch);
  return out;
}

int envmapTableOf(const Scene& scene, const int32_t* counts) {
  if (!scene.tables.followsEnvmapShare()) return -1;
  kern::EnvmapView view = makeEnvmapView(scene.tables, scene.envmap.coskExponent);
  int total = 0;
  for (int k = 0; k < scene.techniqueCount(); ++k) total += counts[k];
  const float alpha0 = (float)counts[0] / (float)total;  // the kernels' stageFractions
  const float share = kern::bankEnvmapFraction(scene.productTables.enabled(), counts[0], counts[1], alpha0);
  // The optimal pdf per pixel is built for the share itself: its bits name the table.
  return scene.tables.hasBank() ? kern::bankEntryOf(view, share) : int(kern::ma_as_uint(share));
}

StageCoefficients optimalCoefficients(StageStatistics& stages, int poolRadius, const StagePlan& first,
                                      const std::vector<int32_t>& next) {
  const Scene& scene = stages.scene();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount(), slots = stages.statSlots();
  std::vector<double> stats = stages.statistics();
  poolNeighbourhood(stats, scene.grid.width, scene.grid.height, slots, poolRadius, scene.surfaces);
  StageCoefficients out{std::vector<float>(size_t(pixels) * 3 * M), std::vector<unsigned char>(pixels)};
#pragma omp parallel for schedule(dynamic, 256)
  for (int p = 0; p < pixels; ++p) {
    if (envmapTableOf(scene, &next[size_t(p) * M]) != envmapTableOf(scene, &first.counts[size_t(p) * M])) {
      out.fallback[p] = kWeightsOtherEnvmapTable;
      continue;
    }
    PixelCoefficients c =
        solveOptimalWeights(optimalWeightsSystem(stats.data() + size_t(p) * slots, stages.config().statsMask, M));
    std::copy(c.a.begin(), c.a.end(), out.coefficients.begin() + size_t(p) * 3 * M);
    out.fallback[p] = (unsigned char)c.fallback;
  }
  return out;
}

RetargetedSums::RetargetedSums(const std::vector<double>& fractions) : techniqueCount(int(fractions.size())) {
  std::copy(fractions.begin(), fractions.end(), beta);
}

void RetargetedSums::add(const double* pdfs, double luminance, double mixture) {
  const double pBeta = mixtureDensity(beta, pdfs, techniqueCount);
  samples += 1;
  if (!(pBeta > 0 && mixture > 0)) return;  // no technique of either mixture reaches x: f = 0 there
  const double weight = 1 / (pBeta * mixture);
  for (int i = 0; i < techniqueCount; ++i) {
    const double wi = weight * pdfs[i];
    for (int k = i; k < techniqueCount; ++k) A[i][k] += wi * pdfs[k];
    bY[i] += wi * luminance;
  }
}

OptimalWeightsSystem RetargetedSums::system(const OptimalWeightsSystem& drawn) const {
  const int M = techniqueCount;
  const double scale = samples > 0 ? 1 / samples : 0;
  OptimalWeightsSystem out{samples, Eigen::MatrixXd(M, M), Eigen::MatrixXd::Zero(M, 3)};
  for (int i = 0; i < M; ++i)
    for (int k = i; k < M; ++k) out.A(i, k) = out.A(k, i) = A[i][k] * scale;
  for (int k = 0; k < M; ++k) {
    const double y = luminance(drawn.b(k, 0), drawn.b(k, 1), drawn.b(k, 2));
    for (int ch = 0; ch < 3; ++ch) out.b(k, ch) = y != 0 ? bY[k] * scale * drawn.b(k, ch) / y : 0.0;
  }
  return out;
}

StageCoefficients retargetedCoefficients(StageStatistics& stages, const StagePlan& stored,
                                         const std::vector<int32_t>& next, int poolRadius) {
  const Scene& scene = stages.scene();
  const int pixels = scene.pixelCount(), M = scene.techniqueCount(), slots = stages.statSlots();
  const int width = scene.grid.width, height = scene.grid.height, capacity = stages.config().sampleCapacity;
  if (stored.stageSamples > capacity) throw std::logic_error("retargetedCoefficients: the stage was not stored whole");
  const std::vector<float> samples = stages.storedSamples();
  std::vector<double> stats = stages.statistics();
  poolNeighbourhood(stats, width, height, slots, poolRadius, scene.surfaces);
  StageCoefficients out{std::vector<float>(size_t(pixels) * 3 * M), std::vector<unsigned char>(pixels)};
#pragma omp parallel for schedule(dynamic, 64)
  for (int p = 0; p < pixels; ++p) {
    std::vector<double> beta(M);
    for (int k = 0; k < M; ++k) beta[k] = double(next[size_t(p) * M + k]);
    const double total = std::accumulate(beta.begin(), beta.end(), 0.0);
    for (double& b : beta) b /= total;
    const int table = envmapTableOf(scene, &next[size_t(p) * M]);
    if (table != envmapTableOf(scene, &stored.counts[size_t(p) * M])) {
      out.fallback[p] = kWeightsOtherEnvmapTable;
      continue;
    }
    RetargetedSums sums(beta);
    double pdfs[kMaxTechniques];
    const int x = p % width, y = p / width;
    for (int qy = std::max(0, y - poolRadius); qy <= std::min(height - 1, y + poolRadius); ++qy)
      for (int qx = std::max(0, x - poolRadius); qx <= std::min(width - 1, x + poolRadius); ++qx) {
        const int q = qy * width + qx;
        if (envmapTableOf(scene, &stored.counts[size_t(q) * M]) != table) continue;
        double drawnFractions[kMaxTechniques];
        for (int k = 0; k < M; ++k) drawnFractions[k] = double(stored.counts[size_t(q) * M + k]) / stored.stageSamples;
        for (int i = 0; i < stored.stageSamples; ++i) {
          for (int k = 0; k < M; ++k) pdfs[k] = samples[kern::storedSampleIndex(q, i, 2 + k, capacity, M)];
          sums.add(pdfs, samples[kern::storedSampleIndex(q, i, 1, capacity, M)],
                   mixtureDensity(drawnFractions, pdfs, M));
        }
      }
    const OptimalWeightsSystem drawn =
        optimalWeightsSystem(stats.data() + size_t(p) * slots, stages.config().statsMask, M);
    PixelCoefficients c = solveOptimalWeights(sums.system(drawn));
    std::copy(c.a.begin(), c.a.end(), out.coefficients.begin() + size_t(p) * 3 * M);
    out.fallback[p] = (unsigned char)c.fallback;
  }
  return out;
}

OptimalWeightsFallbacks countWeightsFallbacks(const std::vector<unsigned char>& fallback) {
  OptimalWeightsFallbacks n;
  for (unsigned char bits : fallback) {
    n.pixels += bits != 0;
    n.tooFewSamples += (bits & kWeightsTooFewSamples) != 0;
    n.illConditioned += (bits & kWeightsIllConditioned) != 0;
    n.nonFinite += (bits & kWeightsNonFinite) != 0;
    n.otherEnvmapTable += (bits & kWeightsOtherEnvmapTable) != 0;
  }
  return n;
}

}  // namespace misalloc
