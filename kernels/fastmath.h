// Inlinable float approximations of log2, exp2, pow, log1p, expm1, sin/cos, acos and atan2.
// OpenCL builtins are opaque calls on PoCL that cost up to ~400 cycles and keep the
// kernel scalar (docs/pocl.md, rule 2); these vectorise.
// tests/test_fastmath.cpp bounds their error against the C++ standard library.
#include "namespace_check.h"
#ifndef MA_FASTMATH_H
#define MA_FASTMATH_H
#include "common.h"

#define MA_LN2 0.69314718055994530942f
#define MA_LOG2E 1.44269504088896340736f

// log2(x) for finite x > 0: exponent plus an atanh series for the mantissa in
// [√½, √2), |t| ≤ 0.1716, so five terms reach float precision. Defined for F = float
// and, in the kernels, float16 (the grid search's entropy rule), lane for lane the same.
#define MA_DEFINE_FAST_LOG2(name, F, U, I, asUint, asFloat, toInt, toFloat)                                         \
  MA_FN F name(F x) {                                                                                               \
    U bits = asUint(x);                                                                                             \
    I e = toInt((bits >> 23) & 0xffu) - 127;                                                                        \
    F m = asFloat((bits & 0x7fffffu) | 0x3f800000u);                                                                \
    I big = m > 1.41421356f ? (I)1 : (I)0;                                                                          \
    m = m > 1.41421356f ? 0.5f * m : m;                                                                             \
    e += big;                                                                                                       \
    F t = (m - 1.0f) / (m + 1.0f);                                                                                  \
    F t2 = t * t;                                                                                                   \
    F series = ma_fma(                                                                                              \
        t2,                                                                                                         \
        ma_fma(t2, ma_fma(t2, ma_fma(t2, (F)(1.0f / 9.0f), (F)(1.0f / 7.0f)), (F)(1.0f / 5.0f)), (F)(1.0f / 3.0f)), \
        (F)1.0f);                                                                                                   \
    return toFloat(e) + 2.0f * MA_LOG2E * t * series;                                                               \
  }
MA_DEFINE_FAST_LOG2(fastLog2, float, ma_uint, int, ma_as_uint, ma_as_float, (int), (float))
#ifdef __OPENCL_VERSION__
MA_DEFINE_FAST_LOG2(fastLog2x16, float16, uint16, int16, as_uint16, as_float16, convert_int16, convert_float16)
#endif

// 2^y: integer part into the exponent, fraction by a degree-7 Taylor series of
// e^g about the middle of [0, 1), |g| ≤ ln2/2. Underflows to 0 below 2^-126.
MA_FN float fastExp2(float y) {
  y = ma_min(ma_max(y, -127.0f), 127.0f);
  float i = ma_floor(y);
  float g = (y - i - 0.5f) * MA_LN2;
  float p = ma_fma(
      g,
      ma_fma(
          g,
          ma_fma(g,
                 ma_fma(g, ma_fma(g, ma_fma(g, ma_fma(g, 1.0f / 5040.0f, 1.0f / 720.0f), 1.0f / 120.0f), 1.0f / 24.0f),
                        1.0f / 6.0f),
                 0.5f),
          1.0f),
      1.0f);
  p *= 1.41421356237309505f;
  int ei = (int)i + 127;
  float scale = ma_as_float((ma_uint)(ei > 0 ? ei : 0) << 23);
  return ei > 0 ? p * scale : 0.0f;
}

// x^y for x ≥ 0, y > 0 (0^y = 0).
MA_FN float fastPow(float x, float y) { return x > 0.0f ? fastExp2(y * fastLog2(x)) : 0.0f; }

// ln(1 + x) for x > -1, accurate to a few ulps relative to the result also where
// |x| is tiny (Goldberg 1991, Thm. 4): with u = fl(1 + x), ln(1 + x) = ln(u) x/(u − 1),
// since u − 1 is exact; x itself where u rounds to 1. No branch: a select.
MA_FN float fastLog1p(float x) {
  float u = 1.0f + x;
  float du = u - 1.0f;
  float q = du != 0.0f ? x / du : 1.0f;
  float l = fastLog2(ma_max(u, 1e-38f)) * MA_LN2;
  return du != 0.0f ? l * q : x;
}

// e^x − 1 for x ≤ 0 (the Phong sampler's range), accurate relative to the result
// also for tiny |x|: a degree-9 Taylor polynomial where |x| < 1/2 (truncation
// < 3e-10 relative), fastExp2 − 1 elsewhere, where no cancellation occurs. A select.
MA_FN float fastExpm1(float x) {
  float series =
      x *
      ma_fma(
          x,
          ma_fma(x,
                 ma_fma(x,
                        ma_fma(x,
                               ma_fma(x,
                                      ma_fma(x, ma_fma(x, ma_fma(x, 1.0f / 362880.0f, 1.0f / 40320.0f), 1.0f / 5040.0f),
                                             1.0f / 720.0f),
                                      1.0f / 120.0f),
                               1.0f / 24.0f),
                        1.0f / 6.0f),
                 0.5f),
          1.0f);
  float direct = fastExp2(x * MA_LOG2E) - 1.0f;
  return ma_abs(x) < 0.5f ? series : direct;
}

typedef struct {
  float s, c;
} MaSinCos;

// sin and cos of 2πu for u in [0, 1]: the quadrant comes from u exactly, the
// remainder |r| ≤ π/4 from two short Taylor polynomials (error ~2e-9).
MA_FN MaSinCos sinCos2Pi(float u) {
  float v = 4.0f * u;
  // ⌊v + ½⌋ by truncation, v ≥ 0. PoCL inlines its floor builtin with branches, and on
  // its haswell target LLVM's SLP vectoriser then pairs the θ and φ rotations of
  // latLongDirection into 2-wide vectors, which keep the envmap technique's sample loop
  // from being vectorised across work-items: 2.8-3.4x slower (docs/pocl.md).
  float q = (float)(int)(v + 0.5f);
  float r = (v - q) * (0.5f * MA_PI);
  float r2 = r * r;
  float sr =
      r * ma_fma(r2, ma_fma(r2, ma_fma(r2, ma_fma(r2, 1.0f / 362880.0f, -1.0f / 5040.0f), 1.0f / 120.0f), -1.0f / 6.0f),
                 1.0f);
  float cr = ma_fma(r2, ma_fma(r2, ma_fma(r2, ma_fma(r2, 1.0f / 40320.0f, -1.0f / 720.0f), 1.0f / 24.0f), -0.5f), 1.0f);
  // Rotate by q quarter turns, with selects rather than branches that vectorise.
  int quadrant = (int)q;
  float sign = (quadrant & 2) ? -1.0f : 1.0f;
  MaSinCos out;
  out.s = sign * ((quadrant & 1) ? cr : sr);
  out.c = sign * ((quadrant & 1) ? -sr : cr);
  return out;
}

// acos(x) on [-1, 1]: Abramowitz & Stegun 4.4.46, |error| ≤ 2e-8 on [0, 1].
MA_FN float fastAcos(float x) {
  float a = ma_min(ma_abs(x), 1.0f);
  float p = ma_fma(
      a,
      ma_fma(
          a,
          ma_fma(
              a,
              ma_fma(a, ma_fma(a, ma_fma(a, ma_fma(a, -0.0012624911f, 0.0066700901f), -0.0170881256f), 0.0308918810f),
                     -0.0501743046f),
              0.0889789874f),
          -0.2145988016f),
      1.5707963050f);
  float r = ma_sqrt(1.0f - a) * p;
  return x < 0.0f ? MA_PI - r : r;
}

// atan2(y, x) mapped to [0, 2π): atan on [0, 1] by Abramowitz & Stegun 4.4.49
// (|error| ≤ 2e-8), extended to all octants.
MA_FN float fastAtan2Positive(float y, float x) {
  // |y| as max(y, −y), not as |x| is: two like absolute values, paired by LLVM's SLP
  // vectoriser, keep a sample loop scalar on PoCL's haswell target (docs/pocl.md, rule 8).
  float ax = ma_abs(x), ay = ma_max(y, -y);
  float hi = ma_max(ma_max(ax, ay), 1e-30f);
  float t = ma_min(ax, ay) / hi;
  float t2 = t * t;
  float p = ma_fma(
      t2,
      ma_fma(t2,
             ma_fma(t2,
                    ma_fma(t2,
                           ma_fma(t2,
                                  ma_fma(t2, ma_fma(t2, ma_fma(t2, 0.0028662257f, -0.0161657367f), 0.0429096138f),
                                         -0.0752896400f),
                                  0.1065626393f),
                           -0.1420889944f),
                    0.1999355085f),
             -0.3333314528f),
      1.0f);
  float r = t * p;
  r = ay > ax ? 0.5f * MA_PI - r : r;
  r = x < 0.0f ? MA_PI - r : r;
  return y < 0.0f ? 2.0f * MA_PI - r : r;
}

#endif
