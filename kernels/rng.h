// Counter-based random numbers: Philox4x32-10 (Random123) keyed by the seed and
// counted by (pixel, stream, sample index, part), so a sample's numbers do not depend on
// the work-group size, the device, or which other samples were taken.
#include "namespace_check.h"
#ifndef MA_RNG_H
#define MA_RNG_H
#include "common.h"
#ifdef __OPENCL_VERSION__
#include <Random123/philox.h>
#endif

// Stream ids: one per technique (0..2), one for the one-sample estimator's choice of
// technique, and one for resampling's choices among candidates (kernels/ris.h).
#define MA_STREAM_TECHNIQUE_CHOICE 7u
#define MA_STREAM_RESAMPLING_CHOICE 8u

typedef struct {
  ma_uint v[4];
} MaRandom4;

// Part `part` of sample `index`'s numbers: a sample that needs more than four words (a
// resampled sample's candidates) counts its further draws in the counter's last word.
MA_FN MaRandom4 philoxDrawPart(ma_uint seedLo, ma_uint seedHi, ma_uint pixel, ma_uint stream, ma_uint index,
                               ma_uint part) {
  philox4x32_ctr_t ctr = {{pixel, stream, index, part}};
  philox4x32_key_t key = {{seedLo, seedHi}};
  philox4x32_ctr_t r = philox4x32_R(10, ctr, key);
  MaRandom4 out;
  out.v[0] = r.v[0];
  out.v[1] = r.v[1];
  out.v[2] = r.v[2];
  out.v[3] = r.v[3];
  return out;
}

MA_FN MaRandom4 philoxDraw(ma_uint seedLo, ma_uint seedHi, ma_uint pixel, ma_uint stream, ma_uint index) {
  return philoxDrawPart(seedLo, seedHi, pixel, stream, index, 0u);
}

// The top 24 bits as a float in [0, 1): exact, never 1.
MA_FN float uniformFloat(ma_uint bits) { return (float)(bits >> 8) * (1.0f / 16777216.0f); }

// ⌈2^24 x⌉ / 2^24 for x ∈ [0, 1]: uniformFloat's u < x holds with exactly this
// probability, so a mixture chosen by such thresholds has the weights the pdf reads.
MA_FN float ceilToUniformGrid(float x) {
  float y = x * 16777216.0f;
  int k = (int)y;
  k += (float)k < y ? 1 : 0;
  return (float)k * (1.0f / 16777216.0f);
}

#endif
