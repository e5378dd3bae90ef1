#pragma once
// Exact's whole-image rule: after the pilot, the gain its allocation predicts over equal
// counts for the image as a whole, at equal time. Where that gain does not pay, the
// render keeps equal counts for every stage after the pilot and says so.

#include <optional>
#include <vector>

#include "alloc/StageAllocator.h"

namespace misalloc {

// The image's predicted efficiency gain of `next` over equal counts, for the stages it
// steers: [Σ_p V_p(equal) · Σ_p c(equal)] / [Σ_p V_p(α_p) · Σ_p c(α_p)] over the covered
// pixels: the image's MSE is the sum of its pixels' variances, its time the sum of their
// costs, c(α) = Σ_k c_k α_k per sample of the kernel that runs those stages ([SHS16]
// eq. 21). The variances are the held-out ones (StageAllocation::heldOutVariance): each
// pixel's own samples judge the weights its neighbours chose, so that the prediction
// is not the selection's own optimism. Pixels without them add no variance. nullopt
// where no pixel has them (no pooled selection); 1 where the pilot saw no variance.
std::optional<double> predictedImageGain(const StageAllocation& next, const std::vector<double>& costs,
                                         const std::vector<unsigned char>& covered);

// The rule: keep equal counts where a gain was predicted and is below `gainBelow`
// (--skip-image-below). The pilot and the allocation are spent by then; what it saves is
// the stages that an allocation predicted to pay too little would have steered.
bool keepsEqualCounts(const std::optional<double>& predictedGain, double gainBelow);

// What the stages after the pilot run where the rule keeps equal counts: equal weights,
// every pixel skipped, and no predicted ratio to weigh the pilot by (StageWeights.h).
StageAllocation equalStageAllocation(int pixels, int techniqueCount);

}  // namespace misalloc
