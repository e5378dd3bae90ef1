#include "distributions/OptimalBank.h"

#include <algorithm>
#include <cmath>

#include "Constants.h"
#include "KernelCode.h"
#include "distributions/BlockCells.h"
#include "distributions/CompensatedPdf.h"

namespace misalloc {
namespace {

// x in [lo, hi] cut into `bins` equal bins: the index of the one holding x (its nearest
// centre). One bin where the range is empty.
struct Axis {
  double lo = 0, hi = 0;
  int bins = 1;

  Axis(const std::vector<double>& values, int requested) {
    lo = *std::min_element(values.begin(), values.end());
    hi = *std::max_element(values.begin(), values.end());
    bins = hi - lo > 1e-9 * std::max(1.0, std::abs(hi)) ? requested : 1;
  }
  int binOf(double x) const {
    if (bins == 1) return 0;
    return std::clamp(int((x - lo) / (hi - lo) * bins), 0, bins - 1);
  }
  double centre(int bin) const { return lo + (bin + 0.5) * (hi - lo) / bins; }
};

// The one-sample estimator's second moment ∫ f²/(q + c p) ([Kar19] eq. 7) with f, q, p
// given as masses per block (F = Σ f = 1).
double secondMoment(const std::vector<double>& f, const std::vector<double>& q, const std::vector<double>& p,
                    double c) {
  double second = 0;
  for (std::size_t b = 0; b < f.size(); ++b)
    if (f[b] > 0) second += f[b] * f[b] / (q[b] + c * p[b]);
  return second;
}

std::vector<double> normalised(std::vector<double> w) {
  double total = 0;
  for (double v : w) total += v;
  for (double& v : w) v /= total;
  return w;
}

}  // namespace

BrdfBins binBrdfs(const BrdfGrid& grid, int exponentBins, int diffuseBins) {
  std::vector<double> logN, diffuse;
  for (const PhongParameters& p : grid.pixels) {
    logN.push_back(std::log(double(p.n)));
    const double albedo = double(p.rhoD) + p.rhoS;
    diffuse.push_back(albedo > 0 ? p.rhoD / albedo : 1.0);  // kernels/phong.h, diffuseLobeWeight
  }
  const Axis exponents(logN, exponentBins), diffuseWeights(diffuse, diffuseBins);
  // Bins no pixel falls in get no table; the others are numbered as pixels first fall in them.
  std::vector<int> index(std::size_t(exponents.bins) * diffuseWeights.bins, -1);
  BrdfBins bins;
  for (std::size_t p = 0; p < logN.size(); ++p) {
    const int cell = exponents.binOf(logN[p]) * diffuseWeights.bins + diffuseWeights.binOf(diffuse[p]);
    if (index[cell] < 0) {
      index[cell] = int(bins.centres.size());
      const double wd = diffuseWeights.centre(cell % diffuseWeights.bins);
      bins.centres.push_back({float(wd), float(1 - wd), float(std::exp(exponents.centre(cell / diffuseWeights.bins)))});
    }
    bins.binOfPixel.push_back(index[cell]);
  }
  return bins;
}

double bankShare(int i, int shares) { return double(i + 1) / double(shares + 1); }

OptimalBankWeights optimalBlockWeights(const std::vector<double>& plainWeights, int width, int height,
                                       const BrdfBins& bins, const std::array<float, 3>& mirror,
                                       const OptimalBankOptions& options) {
  const BlockCells grid = blockCells(plainWeights, width, height, options.blockLog2);
  const std::size_t blocks = grid.plainBlockMass.size();
  OptimalBankWeights bank;
  bank.plainBlockMass = grid.plainBlockMass;
  const std::vector<double>& plainMass = bank.plainBlockMass;
  const int binCount = int(bins.centres.size()), shares = options.shares;
  bank.entries.resize(std::size_t(binCount) * shares);
  std::vector<double> compensatedRatio(bank.entries.size(), 1);
  std::vector<char> negative(bank.entries.size(), 0);
  const kern::MaVec3 r = kern::makeVec3(mirror[0], mirror[1], mirror[2]);
  const kern::MaVec3 up = kern::makeVec3(0.0f, 0.0f, 1.0f);  // a flat scene's normal (flatMirror)
#pragma omp parallel for schedule(dynamic, 1)
  for (int bin = 0; bin < binCount; ++bin) {
    kern::PhongParams b;
    b.rhoD = bins.centres[bin].rhoD;
    b.rhoS = bins.centres[bin].rhoS;
    b.n = bins.centres[bin].n;
    // f = L ρ cos and p_ρ integrated over each block.
    std::vector<double> f(blocks, 0.0), brdf(blocks, 0.0);
    for (const BlockCell& cell : grid.cells) {
      const float lobe = kern::phongLobe(b, cell.direction, r);
      f[cell.block] += cell.plain * kern::phongBrdf(b, lobe) * kern::cosAboveSurface(up, cell.direction);
      brdf[cell.block] += cell.solidAngle * kern::brdfPdf(b, up, cell.direction, lobe);
    }
    double F = 0;
    for (double v : f) F += v;
    if (!(F > 0)) {
      for (int i = 0; i < shares; ++i) bank.entries[std::size_t(bin) * shares + i] = plainMass;
      continue;
    }
    f = normalised(std::move(f));
    brdf = normalised(std::move(brdf));
    // Blocks where f = 0 get p* = 0 for every λ: λ's search and the moments need the
    // others only (about half the sphere is below the horizon).
    std::vector<std::size_t> lit;
    for (std::size_t k = 0; k < blocks; ++k)
      if (f[k] > 0) lit.push_back(k);
    std::vector<double> fLit(lit.size()), brdfLit(lit.size());
    for (std::size_t j = 0; j < lit.size(); ++j) fLit[j] = f[lit[j]], brdfLit[j] = brdf[lit[j]];
    const std::vector<double> ones(lit.size(), 1.0);
    for (int i = 0; i < shares; ++i) {
      const std::size_t entry = std::size_t(bin) * shares + i;
      const double c = bankShare(i, shares);
      std::vector<double> q(lit.size()), optimal(lit.size()), compensated(lit.size());
      for (std::size_t j = 0; j < lit.size(); ++j) q[j] = (1 - c) * brdfLit[j];
      const OptimalLambda lambda = solveOptimalLambda(fLit.data(), q.data(), ones.data(), lit.size(), 1.0, c);
      for (std::size_t j = 0; j < lit.size(); ++j) {
        optimal[j] = optimalFree(fLit[j], q[j], lambda.lambda, c);
        compensated[j] = misCompensated(fLit[j], q[j], 1.0, c);
      }
      // Eq. 5, f/c − q/c, negative beyond rounding somewhere (where f = 0 and q > 0 too).
      for (std::size_t k = 0; k < blocks && !negative[entry]; ++k)
        negative[entry] = f[k] < (1 - c) * brdf[k] * (1 - 1e-9);
      optimal = normalised(std::move(optimal));
      const double best = secondMoment(fLit, q, optimal, c) - 1;
      if (best > 1e-12) compensatedRatio[entry] = (secondMoment(fLit, q, normalised(compensated), c) - 1) / best;
      std::vector<double>& weights = bank.entries[entry];
      weights.assign(blocks, 0.0);
      for (std::size_t j = 0; j < lit.size(); ++j) weights[lit[j]] = optimal[j];
    }
  }
  BankVariances& v = bank.variances;
  v.compensatedOverOptimalMax = *std::max_element(compensatedRatio.begin(), compensatedRatio.end());
  v.compensatedOverOptimalMean = 0;
  for (std::size_t e = 0; e < bank.entries.size(); ++e) {
    v.compensatedOverOptimalMean += compensatedRatio[e] / double(bank.entries.size());
    v.entriesWithNegativeEq5 += negative[e];
  }
  return bank;
}

}  // namespace misalloc
