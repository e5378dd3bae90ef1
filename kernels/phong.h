// Physically corrected Lafortune–Phong BRDF ([HS14] Sec. 5.2, eq. 6.13 with α measured
// from the mirror direction of ω_o) and its two sampling lobes: a cosine lobe about
// the normal and a cos^n lobe about the mirror direction, both in the map's frame. Host side:
// host/scene/BrdfGrid.h holds the per-pixel parameters.
#include "namespace_check.h"
#ifndef MA_PHONG_H
#define MA_PHONG_H
#include "common.h"
#include "fastmath.h"
#include "rng.h"

typedef struct {
  float rhoD, rhoS, n;
} PhongParams;

// 1 − cos α between two unit vectors as |a − b|²/2: accurate relative to itself
// near α = 0, where 1 − dot(a, b) loses every digit at float resolution (1 − cos α
// ≈ 1e-5 for n = 10⁵). For a direction built by directionAboutD, |ω − r|² = 2 d holds
// whatever the rounding of |ω|.
MA_FN float oneMinusCos(MaVec3 a, MaVec3 b) {
  float x = a.x - b.x, y = a.y - b.y, z = a.z - b.z;
  return 0.5f * (x * x + y * y + z * z);
}

// cos^n α, α the angle between ω_i and the mirror direction; 0 beyond 90°. The BRDF
// and both pdfs share it: it is the costliest term of a sample. exp(n ln(1 − d)) with
// d = 1 − cos α computed accurately, so that n up to 10⁵ keeps float precision.
MA_FN float phongLobe(PhongParams b, MaVec3 wi, MaVec3 mirror) {
  float d = oneMinusCos(wi, mirror);
  float lobe = fastExp2(b.n * MA_LOG2E * fastLog1p(-ma_min(d, 0.99999994f)));
  return d < 1.0f ? lobe : 0.0f;
}

// f = ρd/π + ρs (n+2)/(2π) cos^n α.
MA_FN float phongBrdf(PhongParams b, float lobe) {
  return b.rhoD * MA_INV_PI + b.rhoS * (b.n + 2.0f) * (0.5f * MA_INV_PI) * lobe;
}

// cos θ_i against the normal, 0 below the surface.
MA_FN float cosAboveSurface(MaVec3 normal, MaVec3 wi) { return ma_max(dot3(normal, wi), 0.0f); }

// Cosine lobe: p = cos θ / π on the upper hemisphere, given cos θ clamped at the horizon.
MA_FN float diffusePdfOf(float cosAbove) { return cosAbove * MA_INV_PI; }

MA_FN float diffusePdf(MaVec3 normal, MaVec3 wi) { return diffusePdfOf(cosAboveSurface(normal, wi)); }

// Phong lobe about the mirror direction: p = (n+1)/(2π) cos^n α. Part of it may lie
// below the horizon; such samples contribute zero but count.
MA_FN float specularPdf(PhongParams b, float lobe) { return (b.n + 1.0f) * (0.5f * MA_INV_PI) * lobe; }

// The probability of the diffuse lobe in the BRDF×cos technique: its albedo share.
// A black BRDF samples the cosine lobe so that the pdf stays a density.
MA_FN float diffuseLobeWeight(PhongParams b) {
  float albedo = b.rhoD + b.rhoS;
  return albedo > 0.0f ? b.rhoD / albedo : 1.0f;
}

// BRDF×cos technique: the albedo-weighted mixture of the two lobes, given cos θ_i
// clamped at the horizon and the Phong lobe's cos^n α.
MA_FN float brdfPdfOf(PhongParams b, float cosAbove, float lobe) {
  float wd = diffuseLobeWeight(b);
  return wd * diffusePdfOf(cosAbove) + (1.0f - wd) * specularPdf(b, lobe);
}

MA_FN float brdfPdf(PhongParams b, MaVec3 normal, MaVec3 wi, float lobe) {
  return brdfPdfOf(b, cosAboveSurface(normal, wi), lobe);
}

// An orthonormal basis t, s, z about a unit vector z (Duff et al. 2017, branch-free):
// a shading point carries the bases of its two lobes (kernels/estimator.h).
typedef struct {
  MaVec3 t, s, z;
} MaFrame;

MA_FN MaFrame frameAbout(MaVec3 axis) {
  float sign = axis.z >= 0.0f ? 1.0f : -1.0f;
  float a = -1.0f / (sign + axis.z);
  float b = axis.x * axis.y * a;
  MaFrame f;
  f.t = makeVec3(1.0f + sign * axis.x * axis.x * a, sign * b, -sign * axis.x);
  f.s = makeVec3(b, sign + axis.y * axis.y * a, -axis.y);
  f.z = axis;
  return f;
}

// y's sum in fmas, x's and z's in products: three like sums of a direction's
// components are what LLVM's SLP vectoriser pairs into a 2-wide vector on PoCL's
// haswell target (here, or wherever x and y meet later), which keeps the sample loop
// scalar: 4.4x the BRDF technique's time (docs/pocl.md, rule 8).
MA_FN MaVec3 frameToWorld(MaFrame f, float x, float y, float z) {
  return makeVec3(x * f.t.x + y * f.s.x + z * f.z.x, ma_fma(x, f.t.y, ma_fma(y, f.s.y, z * f.z.y)),
                  x * f.t.z + y * f.s.z + z * f.z.z);
}

// A direction about the frame's z with cos = cosAlpha and azimuth 2πu.
MA_FN MaVec3 directionAbout(MaFrame f, float cosAlpha, float u) {
  float sinAlpha = ma_sqrt(ma_max((1.0f - cosAlpha) * (1.0f + cosAlpha), 0.0f));
  MaSinCos phi = sinCos2Pi(u);
  return frameToWorld(f, sinAlpha * phi.c, sinAlpha * phi.s, cosAlpha);
}

// A direction about the frame's z with 1 − cos = d ∈ [0, 2] and azimuth 2πu: sin α =
// √(d (2 − d)) keeps its precision where cos α rounds to 1.
MA_FN MaVec3 directionAboutD(MaFrame f, float d, float u) {
  float sinAlpha = ma_sqrt(ma_max(d * (2.0f - d), 0.0f));
  MaSinCos phi = sinCos2Pi(u);
  return frameToWorld(f, sinAlpha * phi.c, sinAlpha * phi.s, 1.0f - d);
}

// The cosine lobe about the normal, its frame's z.
MA_FN MaVec3 sampleDiffuse(MaFrame normalFrame, float u1, float u2) {
  return directionAbout(normalFrame, ma_sqrt(1.0f - u1), u2);
}

// cos α = u^(1/(n+1)) inverts the CDF of the cos^n lobe (u = 1 − u1 ∈ (0, 1]), taken
// as 1 − cos α = −expm1(ln u / (n+1)) so that it stays exact to float precision for
// n up to 10⁵, where cos α itself is within a few ulps of 1.
MA_FN float specularOneMinusCos(PhongParams b, float u1) {
  return -fastExpm1(fastLog2(1.0f - u1) * MA_LN2 / (b.n + 1.0f));
}

// The Phong lobe about the mirror direction, its frame's z.
MA_FN MaVec3 sampleSpecular(PhongParams b, MaFrame mirrorFrame, float u1, float u2) {
  return directionAboutD(mirrorFrame, specularOneMinusCos(b, u1), u2);
}

// sampleDiffuse's or sampleSpecular's direction, bit for bit, where the lobe is picked
// per sample (the BRDF technique, the one-sample estimator): both lobes' angles, which
// are cheap, then one azimuth and one change of basis.
MA_FN MaVec3 sampleLobe(PhongParams b, MaFrame normalFrame, MaFrame mirrorFrame, int diffuse, float u1, float u2) {
  // sin²α as directionAbout and directionAboutD compute it, (1 − cos)(1 + cos) or
  // d (2 − d), from selected factors: one product, since LLVM's SLP vectoriser pairs two
  // like expressions into a 2-wide vector, and a call in an arm of ?: (ma_max is one)
  // stays a branch; either keeps PoCL's sample loop scalar (docs/pocl.md, rule 8).
  float cosDiffuse = ma_sqrt(1.0f - u1), d = specularOneMinusCos(b, u1);
  float cosAlpha = diffuse ? cosDiffuse : 1.0f - d;
  float p = diffuse ? 1.0f - cosDiffuse : d, q = diffuse ? 1.0f + cosDiffuse : 2.0f - d;
  float sinAlpha = ma_sqrt(ma_max(p * q, 0.0f));
  MaSinCos phi = sinCos2Pi(u2);
  MaFrame f;
  f.t = selectVec3(diffuse, normalFrame.t, mirrorFrame.t);
  f.s = selectVec3(diffuse, normalFrame.s, mirrorFrame.s);
  f.z = selectVec3(diffuse, normalFrame.z, mirrorFrame.z);
  return frameToWorld(f, sinAlpha * phi.c, sinAlpha * phi.s, cosAlpha);
}

MA_FN MaVec3 sampleBrdf(PhongParams b, MaFrame normalFrame, MaFrame mirrorFrame, MaRandom4 rnd) {
  float u1 = uniformFloat(rnd.v[1]), u2 = uniformFloat(rnd.v[2]);
  return sampleLobe(b, normalFrame, mirrorFrame, uniformFloat(rnd.v[0]) < diffuseLobeWeight(b), u1, u2);
}

#endif
