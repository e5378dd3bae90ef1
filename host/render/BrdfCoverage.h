#pragma once
// A compensated envmap pdf ([Kar19] eq. 14) is zero wherever L ≤ 2(1−C)·L̄, so the
// envmap technique alone no longer covers the integrand: MIS with it stays unbiased
// only if BRDF sampling takes at least one sample in every pixel and every stage whose
// estimate is combined ([Kar19] Sec. 4: p_eff > 0 wherever f > 0).
#include "render/Method.h"
#include "render/Render.h"

namespace misalloc {

// Throws InputError when `method` with `estimator` at `spp` could leave a pixel's
// stage without a BRDF sample under a compensated `pdf` (as asked for: a constant map's
// fallback to plain does not lift the refusal), with M techniques: `envmap` alone; a fixed
// multi-sample split, or the oracle's single stage, of fewer than M samples; an
// adaptive stage of fewer than M samples. Render's defensive floor gives every
// technique one sample of each stage, which it can only when the stage has M.
// Nothing to check for the plain pdf, which covers the radiance.
void requireBrdfCoverage(const EnvmapPdf& pdf, int techniqueCount, Method method, Estimator estimator, int spp,
                         const AdaptiveOptions& options);

}  // namespace misalloc
