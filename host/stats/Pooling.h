#pragma once
// Pooled statistics: a pixel's allocation estimated from the sums of its neighbourhood.
// The grids of BRDF parameters vary smoothly across the image, as real surfaces do, so
// neighbouring pixels want nearly the same α, while one pixel's pilot of a few samples
// per technique misjudges the variance of a small bright source by large factors.
// Pooling changes only which α a stage uses, so it keeps every stage unbiased. The grid
// search's pooled selection also predicts how much better that α is than equal counts,
// which weighs the pilot (render/Render.h, pilotWeight): it leaves the pixel's own
// samples out for that (sampling/GridSearch.h, PooledSelection).

#include <vector>

namespace misalloc {

// Replaces each pixel's `channels` values ([pixel · channels + c], row-major pixels of a
// width × height image) by their sums over the (2·radius + 1)² pixels around it,
// clipped at the image's edges. Sums are taken directly, not as running differences,
// which would lose a dim pixel's values beside a million times brighter one.
void poolNeighbourhood(std::vector<double>& values, int width, int height, int channels, int radius);

}  // namespace misalloc
