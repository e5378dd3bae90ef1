// Why a pixel's allocation fell back to a defensive rule: the bits of
// host/alloc/Allocation.h's AllocationFallback (kFallback*, which must equal these;
// host/alloc/GridSearch.cpp checks it), one place for the kernels and the host. The
// grid-search kernel sets the first five; the last two come from host-only rules.
#include "namespace_check.h"
#ifndef MA_FALLBACKS_H
#define MA_FALLBACKS_H

#define MA_FALLBACK_NON_FINITE 1u          // NaN or ∞ in the sums: equal weights
#define MA_FALLBACK_TOO_FEW_SAMPLES 2u     // a technique has too few samples for the estimate: equal weights
#define MA_FALLBACK_NO_SIGNAL 4u           // every sample of the pixel has f = 0: equal weights
#define MA_FALLBACK_SILENT_TECHNIQUE 8u    // a technique saw only f = 0: its weight is 0
#define MA_FALLBACK_ZERO_VARIANCE 16u      // a variance estimate is 0: the formula's limit is used
#define MA_FALLBACK_INFINITE_VARIANCE 32u  // every technique's variance is infinite: equal weights
#define MA_FALLBACK_SINGULAR_SYSTEM 64u    // [SS23] eq. 14 has no unique solution: equal weights over the active set

#endif
