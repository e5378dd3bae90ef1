// Shared between OpenCL C 1.2 kernels and their C++ host references: the same
// functions compile as both, so a host reference runs exactly the kernel's maths.
// In C++ the includer provides <cmath>, <cstdint> and Random123 before this file.
#ifndef MA_COMMON_H
#define MA_COMMON_H

// Every shared function is forced inline: one call left in the sample loop keeps
// PoCL from vectorising across work-items (../shared/notes/pocl-performance.md, rule 1).
#ifdef __OPENCL_VERSION__
#define MA_FN static inline __attribute__((always_inline))
#define MA_GLOBAL __global
#define ma_sqrt(x) sqrt(x)
#define ma_floor(x) floor(x)
#define ma_fma(a, b, c) fma(a, b, c)
#define ma_min(a, b) fmin(a, b)
#define ma_max(a, b) fmax(a, b)
#define ma_abs(x) fabs(x)
#define ma_as_float(u) as_float(u)
#define ma_as_uint(f) as_uint(f)
typedef uint ma_uint;
typedef ulong ma_ulong;
// Loops left in the sample loop make PoCL split it at implicit barriers: unroll them.
#define MA_UNROLL _Pragma("unroll")
#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double ma_acc;  // per-pixel sums; free in the vectorised sampling kernel
#else
typedef float ma_acc;
#endif
#else
#define MA_FN static inline __attribute__((always_inline))
#define MA_GLOBAL
#define ma_sqrt(x) std::sqrt(x)
#define ma_floor(x) std::floor(x)
#define ma_fma(a, b, c) std::fma(a, b, c)
// Plain comparisons: std::fmin and std::fmax are library calls that honour NaNs.
#define ma_min(a, b) ((a) < (b) ? (a) : (b))
#define ma_max(a, b) ((a) > (b) ? (a) : (b))
#define ma_abs(x) std::fabs(x)
typedef uint32_t ma_uint;
typedef uint64_t ma_ulong;
#define MA_UNROLL
typedef double ma_acc;
static inline float ma_as_float(ma_uint u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}
static inline ma_uint ma_as_uint(float f) {
  ma_uint u;
  std::memcpy(&u, &f, 4);
  return u;
}
#endif

#define MA_PI 3.14159265358979323846f
#define MA_INV_PI 0.31830988618379067154f

// The high word of a 32×32-bit product, through a 64-bit multiply that vectorises
// (OpenCL's mul_hi is an opaque call on PoCL).
MA_FN ma_uint mulHi(ma_uint a, ma_uint b) { return (ma_uint)(((ma_ulong)a * (ma_ulong)b) >> 32); }

typedef struct {
  float x, y, z;
} MaVec3;

MA_FN MaVec3 makeVec3(float x, float y, float z) {
  MaVec3 v;
  v.x = x;
  v.y = y;
  v.z = z;
  return v;
}

MA_FN float dot3(MaVec3 a, MaVec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

MA_FN MaVec3 scale3(MaVec3 a, float s) { return makeVec3(a.x * s, a.y * s, a.z * s); }

// Rec.709 luminance, as in ../shared/data/envmaps/README.md.
MA_FN float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

#endif
