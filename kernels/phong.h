// Physically corrected Lafortune–Phong BRDF (000 Sec. 5.2, eq. 6.13 with α measured
// from the mirror direction of ω_o) and its two sampling lobes: a cosine lobe about
// the normal (z) and a cos^n lobe about the mirror direction. Host side:
// host/scene/BrdfGrid.h holds the per-pixel parameters.
#ifndef MA_PHONG_H
#define MA_PHONG_H
#include "common.h"
#include "fastmath.h"
#include "rng.h"

typedef struct {
  float rhoD, rhoS, n;
} PhongParams;

// cos^n α, α the angle between ω_i and the mirror direction; 0 beyond 90°. The BRDF
// and both pdfs share it: it is the costliest term of a sample.
MA_FN float phongLobe(PhongParams b, MaVec3 wi, MaVec3 mirror) { return fastPow(dot3(wi, mirror), b.n); }

// f = ρd/π + ρs (n+2)/(2π) cos^n α.
MA_FN float phongBrdf(PhongParams b, float lobe) {
  return b.rhoD * MA_INV_PI + b.rhoS * (b.n + 2.0f) * (0.5f * MA_INV_PI) * lobe;
}

// Cosine lobe: p = cos θ / π on the upper hemisphere.
MA_FN float diffusePdf(MaVec3 wi) { return ma_max(wi.z, 0.0f) * MA_INV_PI; }

// Phong lobe about the mirror direction: p = (n+1)/(2π) cos^n α. Part of it may lie
// below the horizon; such samples contribute zero but count.
MA_FN float specularPdf(PhongParams b, float lobe) { return (b.n + 1.0f) * (0.5f * MA_INV_PI) * lobe; }

// The probability of the diffuse lobe in the BRDF×cos technique: its albedo share.
// A black BRDF samples the cosine lobe so that the pdf stays a density.
MA_FN float diffuseLobeWeight(PhongParams b) {
  float albedo = b.rhoD + b.rhoS;
  return albedo > 0.0f ? b.rhoD / albedo : 1.0f;
}

// BRDF×cos technique: the albedo-weighted mixture of the two lobes.
MA_FN float brdfPdf(PhongParams b, MaVec3 wi, float lobe) {
  float wd = diffuseLobeWeight(b);
  return wd * diffusePdf(wi) + (1.0f - wd) * specularPdf(b, lobe);
}

// Orthonormal basis about a unit vector (Duff et al. 2017, branch-free).
MA_FN MaVec3 lobeToWorld(MaVec3 axis, float x, float y, float z) {
  float sign = axis.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + axis.z);
  float b = axis.x * axis.y * a;
  MaVec3 t = makeVec3(1.0f + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
  MaVec3 s = makeVec3(b, sign + axis.y * axis.y * a, -axis.y);
  return makeVec3(x * t.x + y * s.x + z * axis.x, x * t.y + y * s.y + z * axis.y, x * t.z + y * s.z + z * axis.z);
}

// A direction about `axis` with cos = cosAlpha and azimuth 2πu.
MA_FN MaVec3 directionAbout(MaVec3 axis, float cosAlpha, float u) {
  float sinAlpha = ma_sqrt(ma_max((1.0f - cosAlpha) * (1.0f + cosAlpha), 0.0f));
  MaSinCos phi = sinCos2Pi(u);
  return lobeToWorld(axis, sinAlpha * phi.c, sinAlpha * phi.s, cosAlpha);
}

MA_FN MaVec3 sampleDiffuse(float u1, float u2) {
  return directionAbout(makeVec3(0.0f, 0.0f, 1.0f), ma_sqrt(1.0f - u1), u2);
}

// cos α = u^(1/(n+1)) inverts the CDF of the cos^n lobe.
MA_FN MaVec3 sampleSpecular(PhongParams b, MaVec3 mirror, float u1, float u2) {
  return directionAbout(mirror, fastPow(1.0f - u1, 1.0f / (b.n + 1.0f)), u2);
}

MA_FN MaVec3 sampleBrdf(PhongParams b, MaVec3 mirror, MaRandom4 rnd) {
  float u1 = uniformFloat(rnd.v[1]), u2 = uniformFloat(rnd.v[2]);
  return uniformFloat(rnd.v[0]) < diffuseLobeWeight(b) ? sampleDiffuse(u1, u2) : sampleSpecular(b, mirror, u1, u2);
}

#endif
