#pragma once
// The refusals that the options alone decide, made before any work: a run that would
// be biased or cannot be carried out is refused with a message naming the options.
#include "render/Method.h"
#include "render/Render.h"

namespace misalloc {

// Whether MIS over the techniques in `sampled` (bit k: technique k takes at least one
// sample of the stage) estimates the integral without bias in every pixel. The balance
// heuristic needs the sampled techniques' pdfs to cover the integrand ([HS14] eq. 4.1:
// p_α > 0 wherever f > 0): the plain envmap pdf covers it, a compensated or optimal
// one does not ([Kar19] Sec. 4: it is zero where the radiance is low); BRDF sampling
// covers it, and with the BRDF split into lobes the diffuse lobe does, the specular lobe
// only its own cone. The count-independent weights ([SHS16] eq. 26) give each technique
// a term that only its own samples estimate: every technique must be sampled. Resampling
// ([TCE05]) draws its candidates from the envmap pdf alone, which must then cover it.
// The product technique (--product) covers it wherever the map is lit, whatever the
// envmap pdf. The techniques' roles and the envmap pdf are the scene's.
bool coversIntegrand(unsigned sampled, const SceneOptions& scene, Estimator estimator);

// Whether a run of `method` with `estimator` (a fixed split's) has the multi-sample
// balance heuristic whose weights [Kon19]'s optimal weights replace (--weights optimal):
// the adaptive methods whose stages are multi-sample, and equal with the multi-sample
// estimator.
bool takesOptimalWeights(Method method, Estimator estimator);

// Whether `method` can sample the product technique (--product): the splits over every
// technique can; envmap, brdf and ris sample a technique of their own and would render
// without it, the option ignored.
bool takesProductTechnique(Method method);

// Throws InputError, before any work, for a run of `method` on `scene` with `spp`
// samples per pixel that the options make impossible (a schedule that does not fit the
// budget, a probe too small, costs of the wrong count, the entropy rule with pooling,
// optimal weights where no multi-sample balance heuristic runs, --product with a method
// that never samples it) or biased: any stage
// whose counts could leave the sampled techniques short of covering the integrand, or a
// technique without a sample in a stage with optimal weights. Render's floor gives every technique one sample of a
// stage of at least M samples; a smaller allocated stage may go to any single technique.
void requireValidRun(const SceneOptions& scene, Method method, Estimator estimator, int spp,
                     const AdaptiveOptions& options);

}  // namespace misalloc
