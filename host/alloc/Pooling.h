#pragma once
// Pooled statistics: a pixel's allocation estimated from the sums of its neighbourhood.
// The grids of BRDF parameters vary smoothly across the image, as real surfaces do, so
// neighbouring pixels want nearly the same α, while one pixel's pilot of a few samples
// per technique misjudges the variance of a small bright source by large factors.
// Pooling changes only which α a stage uses, so it keeps every stage unbiased.
//
// The per-pixel rules (PixelRuleAllocator.h) pool here, on the host, the running sums
// their formulas read, the pixel's own included. The grid search pools something else
// in its own kernel (kernels/gridsearch.cl, selectPooled, whose C++ reference is
// selectPooledPixel in GridSearch.cpp): the scores of each weight combination, each pixel's brought to a
// common scale, and without the pixel itself, because that selection also predicts how
// much better its α is than equal counts, which weighs the pilot (StageWeights.h,
// pilotWeight), and the prediction must not rest on the pilot it weighs
// (GridSearch.h, PooledSelection). The two share only the window's shape, (2r + 1)²
// pixels clipped at the image's edges.

#include <cstdint>
#include <vector>

namespace misalloc {

// Replaces each pixel's `channels` values ([pixel · channels + c], row-major pixels of a
// width × height image) by their sums over the (2·radius + 1)² pixels around it,
// clipped at the image's edges, of its own surface (`surfaces`, Scene::surfaces; empty:
// one surface). Sums are taken directly, not as running differences, which would lose
// a dim pixel's values beside a million times brighter one.
void poolNeighbourhood(std::vector<double>& values, int width, int height, int channels, int radius,
                       const std::vector<int32_t>& surfaces);

}  // namespace misalloc
