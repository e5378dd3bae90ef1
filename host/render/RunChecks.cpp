#include "render/RunChecks.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "Error.h"
#include "KernelCode.h"

namespace misalloc {
namespace {

unsigned allTechniques(int M) { return (1u << M) - 1; }

// The techniques of `scene` whose role is one of `roles`.
unsigned techniquesOf(const SceneOptions& scene, std::initializer_list<int> roles) {
  unsigned set = 0;
  for (int k = 0; k < scene.techniqueCount(); ++k)
    if (std::find(roles.begin(), roles.end(), scene.techniqueRole(k)) != roles.end()) set |= 1u << k;
  return set;
}

// Whether a technique covers, alone, every direction where the integrand is non-zero:
// BRDF sampling and its diffuse lobe wherever the BRDF is non-zero, the product technique
// wherever the map is lit (its plain envmap share, kernels/product.h), the envmap's with
// the plain pdf alone. The specular lobe covers only its own cone.
bool coversAlone(int role, const EnvmapPdf& pdf) {
  return role == kern::ROLE_BRDF || role == kern::ROLE_DIFFUSE || role == kern::ROLE_PRODUCT ||
         (role == kern::ROLE_ENVMAP && pdf.plain());
}

// The techniques a fixed split samples in every pixel that needs them: `envmap`, `ris`
// and `brdf` their own, `equal` the first min(spp, M) (methodCounts hands out the
// remainder from technique 0 on).
unsigned fixedSplitTechniques(const SceneOptions& scene, Method method, int spp) {
  switch (method) {
    case Method::Envmap:
    case Method::Ris:
      return techniquesOf(scene, {kern::ROLE_ENVMAP});
    case Method::Brdf:  // with lobes: the diffuse one wherever its albedo is non-zero (methodCounts)
      return techniquesOf(scene, {kern::ROLE_BRDF, kern::ROLE_DIFFUSE});
    default:
      return allTechniques(std::min(spp, scene.techniqueCount()));
  }
}

// An allocated stage of `samples` samples: all techniques once the floor can give each
// one, else any single technique.
bool allocatedStageCovers(const SceneOptions& scene, int samples, Estimator estimator) {
  const int M = scene.techniqueCount();
  if (samples >= M) return coversIntegrand(allTechniques(M), scene, estimator);
  for (int k = 0; k < M; ++k)
    if (!coversIntegrand(1u << k, scene, estimator)) return false;
  return true;
}

std::string biasReason(const SceneOptions& scene, Estimator estimator) {
  if (estimator == Estimator::CountIndependent)
    return "the count-independent estimator ([SHS16] eq. 26) needs a sample of every technique in every stage";
  if (!scene.envmapPdf.plain())
    return fmt::format(
        "the {} envmap pdf is zero where the radiance is low, so BRDF sampling must take a sample in "
        "every stage",
        envmapPdfName(scene.envmapPdf));
  return techniquesOf(scene, {kern::ROLE_SPECULAR}) != 0
             ? "the specular lobe alone misses the diffuse lobe, so every stage needs a sample of each technique"
             : "every stage needs a sample of each technique";
}

void requireCoveredStages(const SceneOptions& scene, Method method, Estimator estimator, int spp,
                          const AdaptiveOptions& options) {
  const int M = scene.techniqueCount();
  const EnvmapPdf& pdf = scene.envmapPdf;
  const MethodTraits& traits = methodTraits(method);
  if (traits.envmapOnly && !pdf.plain())
    throw InputError(fmt::format(
        "--method {} with --envmap-pdf {}: the pdf is zero where BRDF sampling alone covers the integrand "
        "(compensated: where the radiance is at or below 2(1-C) times its mean), so {} would be biased; use "
        "--envmap-pdf plain, or a method that also samples the BRDF",
        traits.name, envmapPdfName(pdf),
        traits.estimator == Estimator::Resampled ? "resampling envmap candidates ([TCE05])" : "envmap sampling alone"));
  if (traits.split == Split::Fixed) {
    if (coversIntegrand(fixedSplitTechniques(scene, method, spp), scene, estimator)) return;
    throw InputError(
        fmt::format("--spp {} with --method {}{}: the split leaves a technique without samples, and {}; "
                    "raise --spp",
                    spp, methodName(method), pdf.plain() ? "" : " and --envmap-pdf " + envmapPdfName(pdf),
                    biasReason(scene, estimator)));
  }
  std::vector<int> sizes{spp};
  if (traits.split == Split::Staged) sizes = stageSizes(options.pilotFraction, options.stages, spp, M, method);
  const int smallest = *std::min_element(sizes.begin(), sizes.end());
  if (!allocatedStageCovers(scene, smallest, traits.estimator))
    throw InputError(fmt::format(
        "--spp {} with --method {}{}: a stage of {} sample(s) cannot give each of the {} techniques one, and {}; "
        "raise --spp{}",
        spp, methodName(method), pdf.plain() ? "" : " and --envmap-pdf " + envmapPdfName(pdf), smallest, M,
        biasReason(scene, traits.estimator), traits.split == Split::Staged ? " or lower --stages" : ""));
}

// [Kon19]'s optimal weights replace the multi-sample balance heuristic of a method's
// stages: a single technique has no weights to choose, σ/√c allocates for its
// count-independent weights, and the one-sample estimator has no counts n_k to weigh by.
// Each stage must give every technique a sample: Σ_k a_k enters through technique k's
// samples (kernels/pixel.h, withOptimalWeights).
void requireOptimalWeightsRun(const SceneOptions& scene, Method method, Estimator estimator, int spp,
                              const AdaptiveOptions& options) {
  if (options.weights != MisWeights::Optimal) return;
  const MethodTraits& traits = methodTraits(method);
  const int M = scene.techniqueCount();
  if (!takesOptimalWeights(method, estimator))
    throw InputError(fmt::format(
        "--weights optimal with --method {}{}: [Kon19]'s optimal weights replace the multi-sample balance heuristic "
        "of a split over every technique; {}; use --weights balance, or equal, heuristic, linear, exact or oracle",
        traits.name, traits.adaptive() || estimator == Estimator::MultiSample ? "" : " --estimator one",
        traits.adaptive()         ? "its stages use the count-independent weights ([SHS16] eq. 26) it allocates for"
        : method != Method::Equal ? "one technique has no weights to choose"
                                  : "the one-sample estimator has no counts to weigh by"));
  if (options.poolRadius < 0)
    throw InputError(fmt::format("--pool {}: the radius must be at least 0", options.poolRadius));
  if (traits.split == Split::Staged && traits.searchesWeights && options.gridRule == GridRule::MaxEntropy)
    throw InputError(
        "--weights optimal with --grid-rule entropy: [HS14] eq. 4.16 ranks the balance heuristic; use --grid-rule "
        "variance, which ranks the variance of the optimal weights");
  std::vector<int> sizes{spp};
  if (traits.split != Split::Probed)
    sizes = stageSizes(options.pilotFraction, traits.adaptive() ? options.stages : 1, spp, M, method);
  const int smallest = *std::min_element(sizes.begin(), sizes.end());
  if (smallest < M)
    throw InputError(
        fmt::format("--spp {} with --weights optimal: a stage of {} sample(s) cannot give each of the {} "
                    "techniques one, and the optimal weights need a sample of each in every stage; raise "
                    "--spp{}",
                    spp, smallest, M, traits.split == Split::Staged ? " or lower --stages" : ""));
}

}  // namespace

bool takesOptimalWeights(Method method, Estimator estimator) {
  const MethodTraits& traits = methodTraits(method);
  return traits.adaptive() ? traits.estimator == Estimator::MultiSample
                           : method == Method::Equal && estimator == Estimator::MultiSample;
}

bool coversIntegrand(unsigned sampled, const SceneOptions& scene, Estimator estimator) {
  if (estimator == Estimator::CountIndependent) return sampled == allTechniques(scene.techniqueCount());
  if (estimator == Estimator::Resampled)
    return scene.envmapPdf.plain() && (sampled & techniquesOf(scene, {kern::ROLE_ENVMAP})) != 0;
  for (int k = 0; k < scene.techniqueCount(); ++k)
    if ((sampled >> k & 1u) && coversAlone(scene.techniqueRole(k), scene.envmapPdf)) return true;
  return false;
}

bool takesProductTechnique(Method method) {
  return method != Method::Envmap && method != Method::Brdf && method != Method::Ris;
}

void requireValidRun(const SceneOptions& scene, Method method, Estimator estimator, int spp,
                     const AdaptiveOptions& options) {
  const MethodTraits& traits = methodTraits(method);
  const int M = scene.techniqueCount();
  if (scene.product && !takesProductTechnique(method))
    throw InputError(fmt::format(
        "--product with --method {}: {} samples {} alone and never the product technique; drop --product, or use "
        "equal, heuristic, sigma-sqrt-c, linear, exact or oracle",
        traits.name, traits.name, method == Method::Brdf ? "the BRDF" : "the envmap"));
  if (traits.fixesEstimator() && estimator != Estimator::MultiSample && estimator != traits.estimator)
    throw InputError(fmt::format("--estimator: --method {} {}", traits.name,
                                 traits.adaptive() ? "takes multi-sample stages"
                                                   : "is an estimator of its own (resampled importance sampling)"));
  if (traits.estimator == Estimator::Resampled && options.risCandidates < 1)
    throw InputError(fmt::format("--ris-candidates {}: a sample needs at least one candidate", options.risCandidates));
  if (traits.adaptive() && !options.costs.empty() && int(options.costs.size()) != M)
    throw InputError(fmt::format("--cost: {} technique(s) need {} costs, not {}", M, M, options.costs.size()));
  if (traits.split == Split::Probed && options.oracleSamples < 2 * M)
    throw InputError(
        fmt::format("--oracle-spp {}: the probe needs at least 2 samples per technique", options.oracleSamples));
  if (traits.searchesWeights && options.gridSize < 2)
    throw InputError(fmt::format("--grid-u {}: the search needs at least 2 weight combinations", options.gridSize));
  if (traits.split == Split::Staged) {
    if (options.poolRadius < 0)
      throw InputError(fmt::format("--pool {}: the radius must be at least 0", options.poolRadius));
    if (!(options.minGain >= 0 && options.minGain < 1))
      throw InputError(fmt::format("--skip-below {}: the gain must lie in [0, 1)", options.minGain));
    if (!(options.imageGainBelow >= 0 && std::isfinite(options.imageGainBelow)))
      throw InputError(
          fmt::format("--skip-image-below {}: the gain must be finite and at least 0", options.imageGainBelow));
    if (traits.searchesWeights && options.gridRule == GridRule::MaxEntropy && options.poolRadius > 0)
      throw InputError("--grid-rule entropy ranks every pixel by itself: give --pool 0");
  }
  requireCoveredStages(scene, method, estimator, spp, options);
  requireOptimalWeightsRun(scene, method, estimator, spp, options);
}

}  // namespace misalloc
