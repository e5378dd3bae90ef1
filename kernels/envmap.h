// The lat-long environment map: radiance lookup, its sampling pdf (∝ luminance ×
// sin θ per texel, uniform in (φ, θ) inside the texel) and the two samplers with that
// same pdf: an O(1) alias table and marginal/conditional CDFs with binary searches.
// Host side: host/scene/Envmap.h, host/scene/EnvmapDistribution.h.
#include "namespace_check.h"
#ifndef MA_ENVMAP_H
#define MA_ENVMAP_H
#include "common.h"
#include "fastmath.h"
#include "rng.h"

// Row 0 is the zenith: texel (col, row) covers φ ∈ 2π[col, col+1)/W and
// θ ∈ π[row, row+1)/H, with z up.
typedef struct {
  MA_GLOBAL const float* texels;        // per texel: R, G, B, probability of the texel
  MA_GLOBAL const float* cdfTable;      // CDF: marginal (H+1) then conditionals H×(W+1)
  MA_GLOBAL const ma_uint* aliasTable;  // alias: per bucket, acceptance probability bits and alias
  int width, height;
  int useCdf;
  int cdfStepsRow, cdfStepsCol;  // ceil(log2(H)), ceil(log2(W)): fixed-step binary searches
  float coskExponent;            // ≥ 0: analytic radiance cos^K θ on the upper hemisphere ([HS14] App. D)
} EnvmapView;

typedef struct {
  float r, g, b;
  float pdf;  // solid-angle pdf of envmap sampling
} EnvmapHit;

MA_FN MaVec3 latLongDirection(float u, float v) {
  MaSinCos theta = sinCos2Pi(0.5f * v);
  MaSinCos phi = sinCos2Pi(u);
  return makeVec3(theta.s * phi.c, theta.s * phi.s, theta.c);
}

MA_FN int texelOfDirection(EnvmapView env, MaVec3 w) {
  float theta = fastAcos(w.z);
  float phi = fastAtan2Positive(w.y, w.x);
  int row = (int)(theta * ((float)env.height * MA_INV_PI));
  int col = (int)(phi * ((float)env.width * (0.5f * MA_INV_PI)));
  row = row < 0 ? 0 : (row >= env.height ? env.height - 1 : row);
  col = col < 0 ? 0 : (col >= env.width ? env.width - 1 : col);
  return row * env.width + col;
}

// A texel picked with probability P is spread uniformly over its (u, v) area 1/(WH),
// and dω = 2π² sin θ du dv, so p(ω) = P W H / (2π² sin θ).
MA_FN float envmapPdfOfTexel(EnvmapView env, float texelProbability, float sinTheta) {
  return texelProbability * (float)env.width * (float)env.height / (2.0f * MA_PI * MA_PI * ma_max(sinTheta, 1e-7f));
}

// Radiance and pdf at ω inside texel t.
MA_FN EnvmapHit envmapTexelHit(EnvmapView env, int t, MaVec3 w) {
  EnvmapHit hit;
  if (env.coskExponent >= 0.0f) {
    hit.r = hit.g = hit.b = w.z > 0.0f ? fastPow(w.z, env.coskExponent) : 0.0f;
  } else {
    hit.r = env.texels[4 * t + 0];
    hit.g = env.texels[4 * t + 1];
    hit.b = env.texels[4 * t + 2];
  }
  hit.pdf = envmapPdfOfTexel(env, env.texels[4 * t + 3], ma_sqrt(w.x * w.x + w.y * w.y));
  return hit;
}

MA_FN EnvmapHit envmapLookup(EnvmapView env, MaVec3 w) { return envmapTexelHit(env, texelOfDirection(env, w), w); }

// Vose alias table. The bucket comes from a full 32-bit integer and the coin from an
// independent uniform: one 24-bit uniform for both is biased for large tables.
MA_FN int sampleAliasTable(EnvmapView env, ma_uint bucketBits, float coin) {
  ma_uint bucket = mulHi(bucketBits, (ma_uint)(env.width * env.height));
  float accept = ma_as_float(env.aliasTable[2 * bucket]);
  return coin < accept ? (int)bucket : (int)env.aliasTable[2 * bucket + 1];
}

// The last index i in [0, n) with cdf[i] ≤ u, cdf[0] = 0 ≤ u < 1 = cdf[n]: a
// branchless search with a fixed number of steps, so every work-item runs the same code.
MA_FN int searchCdf(MA_GLOBAL const float* cdf, int n, int steps, float u) {
  int base = 0;
  MA_UNROLL
  for (int s = 0; s < steps; ++s) {
    int step = n >> 1;
    base = cdf[base + step] <= u ? base + step : base;
    n -= step;
  }
  return base;
}

MA_FN int sampleCdfTable(EnvmapView env, float uRow, float uCol) {
  MA_GLOBAL const float* marginal = env.cdfTable;
  int row = searchCdf(marginal, env.height, env.cdfStepsRow, uRow);
  MA_GLOBAL const float* conditional = env.cdfTable + (env.height + 1) + row * (env.width + 1);
  int col = searchCdf(conditional, env.width, env.cdfStepsCol, uCol);
  return row * env.width + col;
}

typedef struct {
  MaVec3 w;
  int texel;  // the texel drawn, which holds w
} EnvmapSample;

// The pdf of a drawn direction is that of the texel it was drawn in (as pbrt-v4's
// ImageInfiniteLight::SampleLi): envmapTexelHit then needs no texelOfDirection, whose
// inverse trigonometry and dependent gather would follow the alias table's gather.
// Both agree except where rounding puts w on a neighbouring texel's edge.
MA_FN EnvmapSample sampleEnvmap(EnvmapView env, MaRandom4 rnd) {
  int t = env.useCdf ? sampleCdfTable(env, uniformFloat(rnd.v[0]), uniformFloat(rnd.v[1]))
                     : sampleAliasTable(env, rnd.v[0], uniformFloat(rnd.v[1]));
  int row = t / env.width;
  int col = t - row * env.width;
  float u = ((float)col + uniformFloat(rnd.v[2])) / (float)env.width;
  float v = ((float)row + uniformFloat(rnd.v[3])) / (float)env.height;
  EnvmapSample s;
  s.w = latLongDirection(u, v);
  s.texel = t;
  return s;
}

#endif
