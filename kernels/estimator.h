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
#include "pixel_optimal.h"
#include "product.h"
#include "rng.h"

// What a technique samples, its role, named once for the kernels and the host
// (host/scene/Scene.h): technique 0 samples the envmap; technique 1 BRDF × cos (the
// mixture of both lobes) or, with the BRDF split into lobes (--split-brdf), the cosine
// lobe; technique 2 the Phong lobe (--split-brdf) or envmap × BRDF × cos (--product,
// kernels/product.h).
enum { ROLE_ENVMAP, ROLE_BRDF, ROLE_DIFFUSE, ROLE_SPECULAR, ROLE_PRODUCT, ROLE_COUNT };
#define MA_TECHNIQUE_ENVMAP 0  // the envmap's technique in every set

MA_FN int techniqueRole(int splitBrdf, int product, int technique) {
  if (technique == MA_TECHNIQUE_ENVMAP) return ROLE_ENVMAP;
  if (technique == 1) return splitBrdf ? ROLE_DIFFUSE : ROLE_BRDF;
  return product ? ROLE_PRODUCT : ROLE_SPECULAR;
}

// The point a pixel shades, as every technique's sample and pdf read it (pbrt-v4's
// LightSampleContext, Mitsuba 3's Interaction): its BRDF, and the frames (frameAbout)
// of its shading normal and of the mirror direction of its view ω_o about it, in the
// map's frame (kernels/envmap.h). The map and its pdfs stay in that frame: only the
// BRDF's lobes and cos θ_i turn with the normal.
typedef struct {
  PhongParams brdf;
  MaFrame normalFrame;  // z: the normal
  MaFrame mirrorFrame;  // z: the mirror direction
} ShadingPoint;

typedef struct {
  int techniqueCount;             // M
  int splitBrdf;                  // M = 3: the BRDF's lobes are techniques of their own
  ProductView product;            // productEnabled: technique 2 is the product technique
  ProductMixture productMixture;  // the pixel's (productMixture)
  int sharePdfs;                  // 1: evaluateSample also gives the envmap's pdf under every share's table
} TechniqueSet;

typedef struct {
  MaVec3 wi;
  int texel;  // techniques that draw a texel (drawsTexel): the envmap texel it drew wi in
} TechniqueSample;

MA_FN int roleOf(TechniqueSet ts, int technique) {
  return techniqueRole(ts.splitBrdf, productEnabled(ts.product), technique);
}

MA_FN int isProductTechnique(TechniqueSet ts, int technique) { return roleOf(ts, technique) == ROLE_PRODUCT; }

MA_FN int drawsTexel(TechniqueSet ts, int technique) {
  int role = roleOf(ts, technique);
  return role == ROLE_ENVMAP || role == ROLE_PRODUCT;
}

// mixtureU: the product technique's choice of table (sampleProduct); unused by the others.
MA_FN TechniqueSample sampleTechnique(TechniqueSet ts, EnvmapView env, ShadingPoint sp, int technique, MaRandom4 rnd,
                                      float mixtureU) {
  TechniqueSample s;
  s.texel = 0;
  int role = roleOf(ts, technique);
  if (drawsTexel(ts, technique)) {
    EnvmapSample e =
        role == ROLE_ENVMAP ? sampleEnvmap(env, rnd) : sampleProduct(env, ts.product, ts.productMixture, rnd, mixtureU);
    s.wi = e.w;
    s.texel = e.texel;
  } else if (role == ROLE_BRDF) {
    s.wi = sampleBrdf(sp.brdf, sp.normalFrame, sp.mirrorFrame, rnd);
  } else {
    float u1 = uniformFloat(rnd.v[1]), u2 = uniformFloat(rnd.v[2]);
    s.wi = sampleLobe(sp.brdf, sp.normalFrame, sp.mirrorFrame, role == ROLE_DIFFUSE, u1, u2);
  }
  return s;
}

// p_k(ω_i) of every technique (0 past the last), given the envmap's pdf and the Phong
// lobe at ω_i, which lies in texel t at sin θ = sinTheta.
MA_FN void techniquePdfs(TechniqueSet ts, EnvmapView env, ShadingPoint sp, MaVec3 wi, int t, float sinTheta,
                         float envmapPdf, float lobe, float* pdfs) {
  MA_UNROLL
  for (int k = 0; k < MA_MAX_TECHNIQUES; ++k) {
    int role = roleOf(ts, k);
    pdfs[k] = k >= ts.techniqueCount  ? 0.0f
              : role == ROLE_ENVMAP   ? envmapPdf
              : role == ROLE_BRDF     ? brdfPdf(sp.brdf, sp.normalFrame.z, wi, lobe)
              : role == ROLE_DIFFUSE  ? diffusePdf(sp.normalFrame.z, wi)
              : role == ROLE_SPECULAR ? specularPdf(sp.brdf, lobe)
                                      : productPdf(env, ts.product, ts.productMixture, t, envmapPdf, sinTheta);
  }
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
  float sharePdfs[MA_MAX_BANK_SHARES];  // TechniqueSet::sharePdfs: envmapSharePdfs at ω_i, else 0
} SampleValue;

// The envmap's pdf at ω_i in texel t under the table of every share: the bank's entries
// of the pixel's BRDF bin, or the tables the optimal pdf per pixel would build.
MA_FN void envmapSharePdfs(EnvmapView env, int t, float sinTheta, float* pdfs) {
  if (env.pixelCells > 0)
    pixelSharePdfs(env, t, sinTheta, pdfs);
  else
    bankSharePdfs(env, t, sinTheta, pdfs);
}

// f and every p_k at the direction that `technique` drew, in the texel it drew (as
// sampleEnvmap says why) or the one that holds it. A constant `technique` folds the
// envmap lookup to one of its two cases.
MA_FN SampleValue evaluateSample(TechniqueSet ts, EnvmapView env, ShadingPoint sp, int technique,
                                 TechniqueSample sample) {
  MaVec3 wi = sample.wi;
  int texel = drawsTexel(ts, technique) ? sample.texel : texelOfDirection(env, wi);
  EnvmapHit hit = envmapTexelHit(env, texel, wi);
  // cos θ_i against the normal; sin θ of the map's own latitude, for its pdf.
  float cosTheta = cosAboveSurface(sp.normalFrame.z, wi), sinTheta = ma_sqrt(wi.x * wi.x + wi.y * wi.y);
  float lobe = phongLobe(sp.brdf, wi, sp.mirrorFrame.z);
  float brdfCos = phongBrdf(sp.brdf, lobe) * cosTheta;
  SampleValue s;
  s.r = hit.r * brdfCos;
  s.g = hit.g * brdfCos;
  s.b = hit.b * brdfCos;
  techniquePdfs(ts, env, sp, wi, texel, sinTheta, hit.pdf, lobe, s.pdfs);
  MA_UNROLL
  for (int share = 0; share < MA_MAX_BANK_SHARES; ++share) s.sharePdfs[share] = 0.0f;
  if (ts.sharePdfs) envmapSharePdfs(env, texel, sinTheta, s.sharePdfs);
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
