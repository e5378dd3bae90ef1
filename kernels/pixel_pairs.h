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
// render/Band.h). A stage that stores share columns (kernels/stats.h: `exact`'s pilot)
// shares as well: its samples carry the pdfs of the group's table under each share, the
// table they were drawn from, and so judge α_0 for the group's inputs, which are alike.
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

// A pair's table, the mean of its inputs, and whether it serves both: both take samples
// and their inputs are alike.
typedef struct {
  PixelCdfInputs mean;
  int shares;
} PairTable;

MA_FN PairTable pairTableOf(PixelCdfInputs a, PixelCdfInputs b, int bothSample, int cells) {
  PairTable t;
  t.mean = meanTableInputs(a, b);
  t.shares = bothSample && alikeTableInputs(a, b, cells);
  return t;
}

// Places in a row: the first of x's quad, how many of the quad's four places a row
// `width` wide holds, x's partner in its pair, and the first of the quad's other pair.
MA_FN int quadFirst(int x) { return x & ~3; }
MA_FN int quadPlaces(int x, int width) { return width - quadFirst(x) < 4 ? width - quadFirst(x) : 4; }
MA_FN int pairPartner(int x) { return x ^ 1; }
MA_FN int otherPairFirst(int x) { return quadFirst(x) + ((x & 2) ^ 2); }

// The table `pixel` (at place x) samples alone, with its own inputs: where its partner
// lies past the row's end, or its pair does not share.
MA_FN TableGroup ownTable(int pixel, PixelCdfInputs own) {
  TableGroup g;
  g.first = pixel;
  g.size = 1;
  g.inputs = own;
  return g;
}

// Its pair's table, where the pair shares.
MA_FN TableGroup pairGroup(int pixel, int x, PairTable pair) {
  TableGroup g;
  g.first = pixel - (x & 1);
  g.size = 2;
  g.inputs = pair.mean;
  return g;
}

// Its quad's, where both pairs share and their means are alike; else its pair's. The
// quad's inputs are the mean of the pairs' means, the same bits whichever pixel adds
// which. The callers (kernels/sample.cl, pixelTableGroup; the C++ reference) read the
// other pair's inputs only where the pixel's own pair shares and the row holds the quad,
// in this order, so that the two pairs are never computed side by side: LLVM's SLP
// vectoriser would pair them into short vectors (docs/pocl.md, rule 8).
MA_FN TableGroup quadGroup(int pixel, int x, PairTable pair, PairTable other, int cells) {
  if (!(other.shares && alikeTableInputs(pair.mean, other.mean, cells))) return pairGroup(pixel, x, pair);
  TableGroup g;
  g.first = pixel - x + quadFirst(x);
  g.size = 4;
  g.inputs = meanTableInputs(pair.mean, other.mean);
  return g;
}

#endif
