#include "render/BrdfCoverage.h"

#include <fmt/format.h>

#include <algorithm>

#include "Error.h"

namespace misalloc {

void requireBrdfCoverage(const EnvmapPdf& envmapPdf, int techniqueCount, Method method, Estimator estimator, int spp,
                         const AdaptiveOptions& options) {
  if (envmapPdf.plain()) return;
  const std::string pdf = envmapPdfName(envmapPdf);
  if (method == Method::Envmap)
    throw InputError(fmt::format(
        "--method envmap with --envmap-pdf {}: the pdf is zero where BRDF sampling alone covers the integrand "
        "(compensated: where the radiance is at or below 2(1-C) times its mean), so envmap sampling alone would "
        "be biased; use --envmap-pdf plain, or a method that also samples the BRDF",
        pdf));
  const int M = techniqueCount;
  int smallest = spp;
  if (methodTraits(method).split == Split::Staged) {
    std::vector<int> sizes = stageSizes(options.pilotFraction, options.stages, spp, M);
    smallest = *std::min_element(sizes.begin(), sizes.end());
  } else if (!isAdaptive(method) && (method != Method::Equal || estimator == Estimator::OneSample)) {
    return;  // brdf alone, or one-sample MIS, whose mixture pdf includes BRDF sampling
  }
  if (smallest < M)
    throw InputError(fmt::format(
        "--spp {} with --method {} and --envmap-pdf {}: a stage of {} sample(s) cannot give each of the {} "
        "techniques one, and a compensated pdf needs a BRDF sample in every stage; raise --spp or lower --stages",
        spp, methodName(method), pdf, smallest, M));
}

}  // namespace misalloc
