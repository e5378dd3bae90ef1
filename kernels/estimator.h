// Techniques of the envmap × BRDF estimator and one sample of the balance-heuristic
// MIS estimator ([HS14] eq. 4.1–4.3). Host side: host/scene/Scene.h (techniqueCount,
// techniqueNames: the techniques in this order), host/sampling/Sampler.h (the driver of
// kernels/sample.cl) and host/sampling/HostSampler.cpp (its C++ reference).
#include "namespace_check.h"
#ifndef MA_ESTIMATOR_H
#define MA_ESTIMATOR_H
#include "common.h"
#include "envmap.h"
#include "phong.h"
#include "product.h"
#include "rng.h"

// Technique 0 samples the envmap. With the BRDF as one technique, 1 samples BRDF×cos
// (the mixture of both lobes); split into lobes, 1 is the cosine lobe, 2 the Phong lobe.
// With the product technique (kernels/product.h), 2 samples envmap × BRDF × cos.
#define MA_TECHNIQUE_ENVMAP 0
#define MA_TECHNIQUE_PRODUCT 2

typedef struct {
  int techniqueCount;             // M
  int splitBrdf;                  // M = 3: the BRDF's lobes are techniques of their own
  MaVec3 mirror;                  // mirror direction of ω_o about the normal (z)
  ProductView product;            // product.tables > 0: technique 2 is the product technique
  ProductMixture productMixture;  // the pixel's (productMixture)
  int sharePdfs;                  // 1: evaluateSample also gives the envmap's pdf under every share of the bank
} TechniqueSet;

typedef struct {
  MaVec3 wi;
  int texel;  // techniques that draw a texel (drawsTexel): the envmap texel it drew wi in
} TechniqueSample;

MA_FN int isProductTechnique(TechniqueSet ts, int technique) {
  return ts.product.tables > 0 && technique == MA_TECHNIQUE_PRODUCT;
}

MA_FN int drawsTexel(TechniqueSet ts, int technique) {
  return technique == MA_TECHNIQUE_ENVMAP || isProductTechnique(ts, technique);
}

// mixtureU: the product technique's choice of table (sampleProduct); unused by the others.
MA_FN TechniqueSample sampleTechnique(TechniqueSet ts, EnvmapView env, PhongParams b, int technique, MaRandom4 rnd,
                                      float mixtureU) {
  TechniqueSample s;
  s.texel = 0;
  if (drawsTexel(ts, technique)) {
    EnvmapSample e = technique == MA_TECHNIQUE_ENVMAP
                         ? sampleEnvmap(env, rnd)
                         : sampleProduct(env, ts.product, ts.productMixture, rnd, mixtureU);
    s.wi = e.w;
    s.texel = e.texel;
  } else if (!ts.splitBrdf) {
    s.wi = sampleBrdf(b, ts.mirror, rnd);
  } else {
    float u1 = uniformFloat(rnd.v[1]), u2 = uniformFloat(rnd.v[2]);
    s.wi = technique == 1 ? sampleDiffuse(u1, u2) : sampleSpecular(b, ts.mirror, u1, u2);
  }
  return s;
}

// p_k(ω_i) of every technique, given the envmap's pdf and the Phong lobe at ω_i, which
// lies in texel t at sin θ = sinTheta.
MA_FN void techniquePdfs(TechniqueSet ts, EnvmapView env, PhongParams b, MaVec3 wi, int t, float sinTheta,
                         float envmapPdf, float lobe, float* pdfs) {
  pdfs[0] = envmapPdf;
  pdfs[1] = ts.splitBrdf ? diffusePdf(wi) : brdfPdf(b, wi, lobe);
  pdfs[2] = ts.splitBrdf            ? specularPdf(b, lobe)
            : ts.product.tables > 0 ? productPdf(env, ts.product, ts.productMixture, t, envmapPdf, sinTheta)
                                    : 0.0f;
}

// [HS14] eq. 4.3: the balance heuristic is importance sampling from Σ_k α_k p_k.
MA_FN float mixturePdf(int techniqueCount, const float* alpha, const float* pdfs) {
  float p = 0.0f;
  MA_UNROLL
  for (int k = 0; k < techniqueCount; ++k) p = ma_fma(alpha[k], pdfs[k], p);
  return p;
}

typedef struct {
  float r, g, b;  // f(ω_i) = L(ω_i) f_r(ω_o, ω_i) cos θ_i
  float pdfs[MA_MAX_TECHNIQUES];
  float sharePdfs[MA_MAX_BANK_SHARES];  // TechniqueSet::sharePdfs: bankSharePdfs at ω_i, else 0
} SampleValue;

// f and every p_k at the direction that `technique` drew, in the texel it drew (as
// sampleEnvmap says why) or the one that holds it. A constant `technique` folds the
// envmap lookup to one of its two cases.
MA_FN SampleValue evaluateSample(TechniqueSet ts, EnvmapView env, PhongParams b, int technique,
                                 TechniqueSample sample) {
  MaVec3 wi = sample.wi;
  int texel = drawsTexel(ts, technique) ? sample.texel : texelOfDirection(env, wi);
  EnvmapHit hit = envmapTexelHit(env, texel, wi);
  float cosTheta = ma_max(wi.z, 0.0f), sinTheta = ma_sqrt(wi.x * wi.x + wi.y * wi.y);
  float lobe = phongLobe(b, wi, ts.mirror);
  float brdfCos = phongBrdf(b, lobe) * cosTheta;
  SampleValue s;
  s.r = hit.r * brdfCos;
  s.g = hit.g * brdfCos;
  s.b = hit.b * brdfCos;
  techniquePdfs(ts, env, b, wi, texel, sinTheta, hit.pdf, lobe, s.pdfs);
  MA_UNROLL
  for (int share = 0; share < MA_MAX_BANK_SHARES; ++share) s.sharePdfs[share] = 0.0f;
  if (ts.sharePdfs) bankSharePdfs(env, texel, sinTheta, s.sharePdfs);
  return s;
}

// The one-sample estimator picks technique k with probability α_k.
MA_FN int chooseTechnique(int techniqueCount, const float* alpha, float u) {
  int k = 0;
  float cdf = alpha[0];
  MA_UNROLL
  for (int j = 1; j < techniqueCount; ++j) {
    k = u >= cdf ? j : k;
    cdf += alpha[j];
  }
  return k;
}

#endif
