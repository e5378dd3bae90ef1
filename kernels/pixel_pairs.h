// Pixels x = 2k and 2k + 1 of a row sample one per-pixel table where their tables
// would be alike (kernels/pixel_optimal.h): built from the mean of their inputs, it
// costs half a build each. Pixels x = 4k … 4k + 3, a quad, sample one where each of its
// pairs would, and the pairs' means are alike too: a quarter of a build each, where the
// surface is flat or smooth at the pixels' scale (a plane, most of a mesh), not where it
// curves within a cell's width in four pixels (a small sphere). Neighbours on a smooth
// surface differ by a fraction of a cell; the table cannot tell them apart much better
// than that. Any table with the coverage rule keeps the estimator unbiased, and these
// keep it: all their pixels draw BRDF samples (which cover their own f), or none does
// (the table's plain share covers every lit texel). The pixels that share a table are
// fixed by their places in their row, so a pixel's table does not depend on the launch
// that samples it: its work-group, its device's tiles, its band (whole rows:
// render/Band.h). A stage that stores share columns (kernels/stats.h) keeps each pixel's
// own table: its samples carry pdfs recomputed from the pixel's own inputs.
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

// The pixels that sample one table: `size` (1, 2 or 4) of a row from `first`, and the
// inputs it is built from.
typedef struct {
  int first, size;
  PixelCdfInputs inputs;
} TableGroup;

// The first place of `x`'s quad in a row `width` pixels wide, and how many of its four
// places the row holds.
MA_FN int quadFirst(int x) { return x & ~3; }
MA_FN int quadPlaces(int x, int width) { return width - quadFirst(x) < 4 ? width - quadFirst(x) : 4; }

// The table that `pixel`, at place x of a row `width` wide, samples, given the inputs of
// the pixels of its quad the row holds (quad[i] at place quadFirst(x) + i) and whether
// each takes samples in the stage: the quad's, its pair's or its own, in a stage that
// stores share columns or not. Every pixel of a quad answers alike from the same inputs,
// and each mean's sums are the same whichever pixel adds them, so all build the same
// table, bit for bit.
MA_FN TableGroup tableGroupOf(int pixel, int x, int width, const PixelCdfInputs* quad, const int* samples,
                              int shareColumns, int cells) {
  int i = x - quadFirst(x), j = i ^ 1, places = quadPlaces(x, width);
  TableGroup g;
  g.first = pixel;
  g.size = 1;
  g.inputs = quad[i];
  if (shareColumns) return g;
  if (places == 4 && samples[0] && samples[1] && samples[2] && samples[3] &&
      alikeTableInputs(quad[0], quad[1], cells) && alikeTableInputs(quad[2], quad[3], cells)) {
    PixelCdfInputs low = meanTableInputs(quad[0], quad[1]), high = meanTableInputs(quad[2], quad[3]);
    if (alikeTableInputs(low, high, cells)) {
      g.first = pixel - i;
      g.size = 4;
      g.inputs = meanTableInputs(low, high);
      return g;
    }
  }
  if (j < places && samples[j] && alikeTableInputs(quad[i], quad[j], cells)) {
    g.first = pixel - (i & 1);
    g.size = 2;
    g.inputs = meanTableInputs(quad[i], quad[j]);
  }
  return g;
}

#endif
