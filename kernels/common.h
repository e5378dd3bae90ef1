// Shared between OpenCL C 1.2 kernels and their C++ host references: the same
// functions compile as both, so a host reference runs exactly the kernel's maths.
// In C++ the includer provides <cmath>, <cstdint> and Random123 before this file.

#include "namespace_check.h"
#ifndef MA_COMMON_H
#define MA_COMMON_H

// Every shared function is forced inline: one call left in the sample loop keeps
// PoCL from vectorising across work-items (docs/pocl.md, rule 1).
#ifdef __OPENCL_VERSION__
#define MA_FN static inline __attribute__((always_inline))
#define MA_GLOBAL __global
#define MA_LOCAL __local
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
// The 64 bits at 8-byte slot i of a buffer of 32-bit words (the first word low). One
// 64-bit read halves a lookup's gathers; where a kernel must keep its loop free of 64-bit
// loads (MA_SPLIT_LOAD64, samplePixelStage: docs/pocl.md, rule 10), two 32-bit reads.
#if MA_SPLIT_LOAD64
#define ma_load64(p, i) upsample(((MA_GLOBAL const ma_uint*)(p))[2 * (i) + 1], ((MA_GLOBAL const ma_uint*)(p))[2 * (i)])
#else
#define ma_load64(p, i) (((MA_GLOBAL const ma_ulong*)(p))[i])
#endif
// Loops left in the sample loop make PoCL split it at implicit barriers: unroll them.
#define MA_UNROLL _Pragma("unroll")
// A loop over a pixel's cells within one work-item (samplePixelStage's lanes, a CPU's)
// at the float16 width: LLVM prefers 256-bit vectors on AVX-512 CPUs (docs/pocl.md).
// MA_CELL_GATHER_LOOP: such a loop that reads the rows at a stride and writes others,
// which LLVM cannot tell apart without a check it does not build: the rows it reads and
// those it writes are asserted disjoint.
#if MA_PIXEL_LANES > 0
#define MA_CELL_LOOP _Pragma("clang loop vectorize_width(16)")
#define MA_CELL_GATHER_LOOP _Pragma("clang loop vectorize(assume_safety) vectorize_width(16)")
#else
#define MA_CELL_LOOP
#define MA_CELL_GATHER_LOOP
#endif
#if defined(cl_khr_fp64)
#pragma OPENCL EXTENSION cl_khr_fp64 : enable
typedef double ma_acc;  // per-pixel sums; free in the vectorised sampling kernel
#else
typedef float ma_acc;
#endif
#else
#define MA_FN static inline __attribute__((always_inline))
#define MA_GLOBAL
#define MA_LOCAL
typedef uint32_t ma_uint;
typedef uint64_t ma_ulong;
#define MA_UNROLL
#define MA_CELL_LOOP
#define MA_CELL_GATHER_LOOP
typedef double ma_acc;
// The OpenCL builtins as functions of float, as the kernels call them: each argument is
// evaluated once, and nothing leaks out of namespace misalloc::kern.
MA_FN float ma_sqrt(float x) { return std::sqrt(x); }
MA_FN float ma_floor(float x) { return std::floor(x); }
MA_FN float ma_fma(float a, float b, float c) { return std::fma(a, b, c); }
MA_FN float ma_abs(float x) { return std::fabs(x); }
// OpenCL's fmin and fmax: a NaN argument loses to a number. Written as comparisons,
// which inline, where std::fmin and std::fmax are library calls; equal arguments give b.
MA_FN float ma_min(float a, float b) { return (a < b || b != b) ? a : b; }
MA_FN float ma_max(float a, float b) { return (a > b || b != b) ? a : b; }
MA_FN float ma_as_float(ma_uint u) {
  float f;
  std::memcpy(&f, &u, 4);
  return f;
}
MA_FN ma_uint ma_as_uint(float f) {
  ma_uint u;
  std::memcpy(&u, &f, 4);
  return u;
}
MA_FN ma_ulong ma_load64(const void* p, int i) {
  ma_ulong v;
  std::memcpy(&v, static_cast<const char*>(p) + 8 * size_t(i), 8);
  return v;
}
#endif

// The most techniques the kernels handle, one place for both. The sampling kernel
// draws from at most 3: the envmap and the BRDF, or the envmap and the BRDF's two lobes
// (--split-brdf); its per-sample arrays have this size. The statistics and the grid
// search take up to 4 (the papers' 1D examples have up to 4 techniques); host code
// calls that kMaxTechniques (host/stats/PixelStats.h).
#define MA_MAX_TECHNIQUES 3
#define MA_GRID_MAX_TECHNIQUES 4
#if MA_MAX_TECHNIQUES > MA_GRID_MAX_TECHNIQUES
#error "the statistics must hold every technique the sampler draws from"
#endif

#define MA_PI 3.14159265358979323846f
#define MA_INV_PI 0.31830988618379067154f

// The high word of a 32×32-bit product, through a 64-bit multiply that vectorises
// (OpenCL's mul_hi is an opaque call on PoCL).
MA_FN ma_uint mulHi(ma_uint a, ma_uint b) { return (ma_uint)(((ma_ulong)a * (ma_ulong)b) >> 32); }

// Low and high 32-bit words of a 64-bit read (ma_load64). Two words read as one halve
// the gathers of a table lookup; on PoCL's haswell target, which has no gather
// instruction, each gather is one scalar load per lane (docs/pocl.md).
MA_FN ma_uint lowWord(ma_ulong v) { return (ma_uint)v; }
MA_FN ma_uint highWord(ma_ulong v) { return (ma_uint)(v >> 32); }

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

// c ? a : b, component by component: a conditional between two structs compiles to a
// branch, which keeps PoCL's work-item loop from being vectorised; between floats it is
// a select.
MA_FN MaVec3 selectVec3(int c, MaVec3 a, MaVec3 b) { return makeVec3(c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z); }

MA_FN float dot3(MaVec3 a, MaVec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

MA_FN MaVec3 scale3(MaVec3 a, float s) { return makeVec3(a.x * s, a.y * s, a.z * s); }

// Rec. 709 luminance, the maps' colour space (data/envmaps/README.md). Host code in
// double: misalloc::luminance (host/Constants.h), the same weights.
MA_FN float luminance(float r, float g, float b) { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }

// The root mean square of a colour's channels: one number whose square is the mean of
// the channels' squares, as the error over RGB that compare measures weighs them
// (kernels/stats.h, storedSampleValue); luminance weighs blue by 0.07.
MA_FN float channelRms(float r, float g, float b) { return ma_sqrt((r * r + g * g + b * b) * (1.0f / 3.0f)); }

#endif
