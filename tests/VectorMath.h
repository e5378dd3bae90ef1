#pragma once
// Vectors in double for the tests' geometry checks, which recompute in double what the
// host computes in float.
#include <cmath>

#include "scene/GBuffer.h"
#include "scene/SceneGeometry.h"

namespace misalloc::test {

inline Vec3d toDouble(const Vec3f& v) { return {v[0], v[1], v[2]}; }
inline Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline Vec3d scaled(const Vec3d& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
inline Vec3d unit(const Vec3d& a) { return scaled(a, 1 / std::sqrt(dot(a, a))); }

}  // namespace misalloc::test
