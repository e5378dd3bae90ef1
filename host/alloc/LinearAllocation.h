#pragma once
// Szirmay-Kalos & Sbert's linear heuristic ([SS23] Sec. 5): weights from a linear
// equation in the running sums P_ik and F_k of [SS23] eq. 18.

#include <optional>
#include <vector>

#include "alloc/Allocation.h"
#include "stats/PixelSamples.h"

namespace misalloc {

// [SS23] Sec. 5.1: what to do when eq. 14's solution has a negative weight.
enum class ZeroWeightRule {
  DropMostNegative,   // first technique: zero the most negative weight, re-solve, repeat
  MinSampleVariance,  // second technique: zero each weight in turn (then pairs, ...) and keep
                      // the feasible solution with the smallest sample variance (eq. 19)
};

// [SS23] eq. 17 for the techniques i, j alone: α_i, with α_j = 1 − α_i. nullopt if the
// denominator vanishes, i.e. eq. 15 does not determine α.
std::optional<double> linearPairWeight(const PixelStats& stats, int i, int j);

// [SS23] eq. 14 for the techniques whose bit is set in activeMask (the others weigh 0):
// Σ_i α_i P_ik / F_k = 1/μ for every active k, Σ_i α_i = 1, solved for α and 1/μ as
// one dense system. Needs F_k > 0 for active k. nullopt if the system is singular.
// Weights may come out negative; that is for the Sec. 5.1 rules to handle.
std::optional<std::vector<double>> solveLinearSystem(const PixelStats& stats, unsigned activeMask);

// The linear heuristic on running sums alone, so with the first Sec. 5.1 technique.
// Needs n_k ≥ 1. A technique with F_k = 0 (all its samples zero) cannot satisfy
// eq. 8, E_k[f/p] = μ > 0, so its optimal weight is 0: it is left out of the system
// (kFallbackSilentTechnique).
Allocation allocateLinear(const PixelStats& stats);

// The linear heuristic with either Sec. 5.1 technique; the second needs the samples.
Allocation allocateLinear(const PixelSamples& samples, ZeroWeightRule rule = ZeroWeightRule::MinSampleVariance);

}  // namespace misalloc
