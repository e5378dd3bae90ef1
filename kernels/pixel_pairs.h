// Pixels x = 2k and 2k + 1 of a row sample one per-pixel table where their tables
// would be alike (kernels/pixel_optimal.h): built from the mean of their inputs, it
// costs half a build each. Neighbours on a smooth surface differ by a fraction of a
// cell; the table cannot tell them apart much better than that. Any table with the
// coverage rule keeps the estimator unbiased, and the pair's keeps it: both pixels draw
// BRDF samples (which cover their own f), or neither does (the table's plain share
// covers every lit texel). The pair is fixed by the pixels' places in their row, so a
// pixel's table does not depend on the launch that samples it: its work-group, its
// device's tiles, its band (whole rows: render/Band.h). A stage that stores share
// columns (kernels/stats.h) keeps each pixel's own table: its samples carry pdfs
// recomputed from the pixel's own inputs.
#include "namespace_check.h"
#ifndef MA_PIXEL_PAIRS_H
#define MA_PIXEL_PAIRS_H
#include "phong.h"
#include "pixel.h"

// What buildPixelOptimalCdf builds a pixel's table from.
typedef struct {
  PhongParams brdf;
  MaVec3 normal, mirror;
  float envmapShare;  // stageEnvmapShare
  int brdfCovers;     // stageDrawsBrdf
} PixelCdfInputs;

// A pixel's inputs from its shading point and its counts in the stage.
MA_FN PixelCdfInputs cdfInputsOf(PhongParams brdf, MaVec3 normal, MaVec3 mirror, StageCounts c, int product) {
  PixelCdfInputs in;
  in.brdf = brdf;
  in.normal = normal;
  in.mirror = mirror;
  in.envmapShare = stageEnvmapShare(product, c);
  in.brdfCovers = stageDrawsBrdf(c);
  return in;
}

// The other pixel of `pixel`'s pair, in an image `width` pixels wide; −1 for the last
// pixel of a row of odd width.
MA_FN int pairPartner(int pixel, int width) {
  int x = pixel % width, other = x ^ 1;
  return other < width ? pixel - x + other : -1;
}

// Within 5 % of their mean.
MA_FN int alikeValues(float a, float b) { return ma_abs(a - b) <= 0.025f * (a + b); }

// Whether one table serves both a and b, over `cells` cells of N × N/2, N = √(2 cells):
// a cell spans Δ = π/(N/2), Δ² = 2π²/cells. The mean's normal lies within Δ/8 of
// each pixel's, so that the horizon moves by a fraction of a cell. Its mirror lies
// within half the lobe's width as the table spreads it (kernels/pixel_optimal.h,
// cellLobe: 1/κ' = 1/n + 1/κ, κ = 12/Δ² for a cell Δ wide), taking the narrower lobe's
// n: the limits below are on 1 − cos of the angle between the pixels, δ²/2.
MA_FN int alikeTableInputs(PixelCdfInputs a, PixelCdfInputs b, int cells) {
  float cellAngle2 = 2.0f * MA_PI * MA_PI / (float)cells;
  float n = ma_max(a.brdf.n, b.brdf.n);
  float normalLimit = cellAngle2 / 32.0f;
  float mirrorLimit = 0.5f * (1.0f / n + cellAngle2 / 12.0f);
  return a.brdfCovers == b.brdfCovers && ma_abs(a.envmapShare - b.envmapShare) <= 0.0625f &&
         alikeValues(a.brdf.rhoD, b.brdf.rhoD) && alikeValues(a.brdf.rhoS, b.brdf.rhoS) &&
         alikeValues(a.brdf.n, b.brdf.n) && oneMinusCos(a.normal, b.normal) <= normalLimit &&
         oneMinusCos(a.mirror, b.mirror) <= mirrorLimit;
}

MA_FN MaVec3 meanDirection(MaVec3 a, MaVec3 b) {
  MaVec3 sum = makeVec3(a.x + b.x, a.y + b.y, a.z + b.z);
  return scale3(sum, 1.0f / ma_sqrt(dot3(sum, sum)));
}

// The inputs of the pair's table: their mean. Each sum is the same whichever pixel
// adds the other, so both pixels build the same table, bit for bit.
MA_FN PixelCdfInputs meanTableInputs(PixelCdfInputs a, PixelCdfInputs b) {
  PixelCdfInputs m;
  m.brdf.rhoD = 0.5f * (a.brdf.rhoD + b.brdf.rhoD);
  m.brdf.rhoS = 0.5f * (a.brdf.rhoS + b.brdf.rhoS);
  m.brdf.n = 0.5f * (a.brdf.n + b.brdf.n);
  m.normal = meanDirection(a.normal, b.normal);
  m.mirror = meanDirection(a.mirror, b.mirror);
  m.envmapShare = 0.5f * (a.envmapShare + b.envmapShare);
  m.brdfCovers = a.brdfCovers;
  return m;
}

// Whether a pixel samples its pair's table (meanTableInputs), given its own inputs and
// its partner's (pairPartner), which takes samples in the stage or not
// (partnerSamples), in a stage that stores share columns or not. Both pixels of a pair
// answer alike.
MA_FN int pairsTables(PixelCdfInputs own, PixelCdfInputs partner, int partnerSamples, int shareColumns, int cells) {
  return !shareColumns && partnerSamples && alikeTableInputs(own, partner, cells);
}

#endif
