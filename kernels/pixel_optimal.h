// The optimal envmap pdf of [Kar19] for one pixel's own normal, view, BRDF and envmap
// share C, built at run time: every pixel may see the map differently (a real scene),
// and C is the pixel's own α_0. The map is cut into coarse cells, blocks of 2^L × 2^L
// texels (host/distributions/EnvmapDistribution.h, buildPixelOptimalEnvmapTables), each
// with two frames (a mean direction and a spread: its own, and its light's), its share
// of the plain pdf's mass and its solid angle. Per pixel and stage, f = L ρ cos is taken
// at each cell's light and the BRDF technique's p_ρ over the cell, their Phong lobe and
// cosine averaged over the frame's spread (cellLobe, cellCosine), and the cells weighed
// by eq. 6, max(0, f − (1−C) p_ρ) with both normalised: eq. 9 at its bound s = 1/C, which the optimal pdf's bank measures within
// a few percent of eq. 9's variance (render.json, one_sample_variance_eq6_over_eq9_mean).
// Where the stage draws no BRDF samples, a share of the plain pdf keeps every lit cell
// drawable (the cells' means are estimates: a cell weighed 0 may hold lit texels above
// the horizon). Elsewhere BRDF sampling covers every direction where f ≠ 0, and the
// table is eq. 6's alone; so is the product technique's. The pixel's CDF
// over the cells lives in its rows of local memory (kernels/pixel_layout.h); a texel
// within the drawn cell comes from the cell's alias table ∝ luminance × sin θ, as for
// the bank (kernels/envmap.h, sampleEnvmapPixelCells). The pdf a sample is weighed with
// is read from the same CDF, so the estimator is unbiased however coarse the cells are.
//
// The build runs in passes over the cells and over MA_PIXEL_CHUNKS fixed chunks of them
// (kernels/pixel_layout.h, chunkOfCell), its sums added chunk by chunk. Each work-item
// builds its own pixel's table, or its pair's (kernels/pixel_pairs.h), from the inputs
// it is given (sampleStage, and samplePixelStage's lanes one pixel each), so the chunks
// no longer split one build among lanes; they remain the CDF's order.
//
// A stage that stores its samples for the grid search of `exact` (kernels/stats.h, share
// columns) also keeps each cell's mass in the tables that stages of the shares C = 1/4,
// 1/2, 3/4 would build: each sample then carries its pdf under each, and the search judges
// each α_0 by the table of the share nearest it ([Kar19] Sec. 10's joint choice of the
// pdf and the allocation), as it does with the bank's entries.
//
// The product technique ([CL18]) from the same cells (--product with this pdf): its table
// is eq. 6 at C = 1, f/F, with the plain share where the stage draws no BRDF samples. Its
// CDF is written beside the envmap's from the same f, in the same passes: per pixel, with
// no table binned over BRDFs or geometry (kernels/product.h, ProductView::pixelCells).
#include "namespace_check.h"
#ifndef MA_PIXEL_OPTIMAL_H
#define MA_PIXEL_OPTIMAL_H
#include "envmap.h"
#include "phong.h"
#include "pixel_layout.h"

// A cell's floats: two frames (CellFrame, host: EnvmapDistribution.cpp, cellFrames),
// each a mean direction x, y, z and its directions' spread about it, as cellFrameOf
// keeps it (cellLobe, cellCosine): the cell's, its directions weighed by solid angle, where the BRDF technique's mass
// in it lies; and its light's, its texels weighed as its alias table draws them, where
// f's mass lies (a sun in a cell's corner is there, not at the cell's centre), the
// cell's own where it holds no light. Then its share of the plain pdf's mass and its
// solid angle; and its peak (host: cellPeaks), the texels over twice its mean light per
// solid angle, as their share ℓ of its light and ℓ − a, a their share of its solid
// angle (eq6Value). Each float of every cell in turn (field f of cell c at
// cells[f · count + c]), so that a pass over cells side by side reads each float side
// by side.
enum {
  CELL_X,
  CELL_Y,
  CELL_Z,
  CELL_VARIANCE,
  CELL_HALF_WIDTH,
  CELL_RAMP,
  CELL_LIGHT_X,
  CELL_LIGHT_Y,
  CELL_LIGHT_Z,
  CELL_LIGHT_VARIANCE,
  CELL_LIGHT_HALF_WIDTH,
  CELL_LIGHT_RAMP,
  CELL_PLAIN,
  CELL_SOLID_ANGLE,
  CELL_PEAK_LIGHT,
  CELL_PEAK_GAP
};
#define MA_CELL_FLOATS 16
// The plain pdf's share of the pixel's tables where no BRDF sample covers what eq. 6
// leaves out (tableScalesOf): the defensive part.
#define MA_PIXEL_PLAIN_SHARE 0.0625f

// The rows (kernels/pixel_layout.h, MA_PIXEL_CDF_ROWS) from the CDF's first: the CDF's
// count + 1 entries in its order (cdfPositionOfCell), as float bits; then each cell's
// p_ρ mass and its f in the cells' order (pass 4 leaves each cell's table mass in place
// of its f); then
// per chunk its Σ f, Σ p_ρ, Σ plain and Σ of eq. 6's terms. (f in the CDF's rows, at its
// cell's position, would save count rows, but pass 1's stores would no longer lie side
// by side, and the compiler no longer vectorises it: 2.2× the time of the pilot stage.)
#define MA_CDF_ROW(p) (p)
#define MA_BRDF_ROW(count, c) ((count) + 1 + (c))
#define MA_F_ROW(count, c) (2 * (count) + 1 + (c))
enum { CHUNK_F, CHUNK_BRDF, CHUNK_PLAIN, CHUNK_EQ6, CHUNK_SUMS };
#define MA_CHUNK_ROW(count, sum, j) (3 * (count) + 1 + (sum)*MA_PIXEL_CHUNKS + (j))
// Then the product technique's CDF, count + 1 entries.
#define MA_PRODUCT_CDF_ROW(count, c) (MA_CHUNK_ROW(count, CHUNK_SUMS, 0) + (c))
// Then, for the share columns, share s's table's mass in cell c, in the cells' order
// (MA_PIXEL_SHARE_MASS_ROWS, for MA_MAX_BANK_SHARES shares), the product's rows before
// them whether it runs or not. The shares of a cell lie count words apart: adjacent, the
// search's shares, computed alike from adjacent words, would be paired into short
// vectors (docs/pocl.md, rule 8).
#define MA_SHARE_MASS_ROW(count, s, c) (MA_PRODUCT_CDF_ROW(count, (count) + 1) + (s) * (count) + (c))

MA_FN float rowFloat(MA_LOCAL const int* rows, int stride, int r) { return ma_as_float((ma_uint)rows[r * stride]); }
MA_FN void setRowFloat(MA_LOCAL int* rows, int stride, int r, float v) { rows[r * stride] = (int)ma_as_uint(v); }
MA_FN void addToRowFloat(MA_LOCAL int* rows, int stride, int r, float v) {
  setRowFloat(rows, stride, r, rowFloat(rows, stride, r) + v);
}

// Directions about a mean `centre`, with the second moment `variance` about it along
// their wider axis: 1/κ of a cos^κ lobe as wide (cellLobe). An angle spread uniformly
// with that variance spans ±halfWidth, halfWidth = √(3 variance), and rampScale is
// 1/(4 halfWidth) (cellCosine). The three are kept with the cell: taken per cell and
// pixel, their divisions and root cost 4–6 % of the table's build (docs/results.md,
// "Quads of pixels share a table").
typedef struct {
  MaVec3 centre;
  float variance, halfWidth, rampScale;
} CellFrame;

MA_FN CellFrame cellFrameOf(MaVec3 centre, float variance) {
  CellFrame f;
  f.centre = centre;
  f.variance = variance;
  f.halfWidth = ma_sqrt(3.0f * variance);
  f.rampScale = f.halfWidth > 0.0f ? 0.25f / f.halfWidth : 0.0f;
  return f;
}

typedef struct {
  CellFrame area;   // CELL_X … CELL_SPREAD: p_ρ's mass is taken there
  CellFrame light;  // CELL_LIGHT_X … CELL_LIGHT_SPREAD: f's mass is taken there
  float plain, solidAngle;
} PixelCell;

MA_FN float cellField(MA_GLOBAL const float* cells, int count, int c, int field) { return cells[field * count + c]; }

// The frame whose fields start at `first` (CELL_X or CELL_LIGHT_X), in CellFrame's order.
MA_FN CellFrame cellFrameAt(MA_GLOBAL const float* cells, int count, int c, int first) {
  CellFrame f;
  f.centre = makeVec3(cellField(cells, count, c, first), cellField(cells, count, c, first + 1),
                      cellField(cells, count, c, first + 2));
  f.variance = cellField(cells, count, c, first + 3);
  f.halfWidth = cellField(cells, count, c, first + 4);
  f.rampScale = cellField(cells, count, c, first + 5);
  return f;
}

MA_FN PixelCell pixelCellAt(MA_GLOBAL const float* cells, int count, int c) {
  PixelCell cell;
  cell.area = cellFrameAt(cells, count, c, CELL_X);
  cell.light = cellFrameAt(cells, count, c, CELL_LIGHT_X);
  cell.plain = cellField(cells, count, c, CELL_PLAIN);
  cell.solidAngle = cellField(cells, count, c, CELL_SOLID_ANGLE);
  return cell;
}

// The Phong lobe averaged over a frame's directions rather than taken at its centre: a
// lobe narrower than a cell would otherwise weigh the cell by its tail at the centre,
// and a glossy pixel's table would miss the cell that holds its lobe. cos^κ spreads a
// direction by 1/κ per axis, and a frame's directions by its variance (a cell at a pole
// is a narrow wedge: the wider axis's), so that cos^n about the mirror direction spread
// by the frame is cos^κ' with 1/κ' = 1/n + variance (variances add),
// κ' = n/(1 + n variance), scaled by (κ'+1)/(n+1) so that the lobe keeps its mass
// 2π/(n+1). 1/(n+1) is the pixel's, out of the loops over cells.
MA_FN float cellLobe(PhongParams b, CellFrame frame, MaVec3 mirror) {
  PhongParams spread = b;
  spread.n = b.n / ma_fma(b.n, frame.variance, 1.0f);
  return (spread.n + 1.0f) * (1.0f / (b.n + 1.0f)) * phongLobe(spread, frame.centre, mirror);
}

// max(0, cos θ) averaged over a frame's directions rather than taken at its centre, so
// that a cell that straddles the horizon keeps the part above it: the angle above the
// horizon spread uniformly by ±w about the centre's (w the frame's halfWidth), in its
// small-angle form, (c + w)²/(4w): the centre's value where the frame lies wholly
// above, 0 below.
MA_FN float cellCosine(MaVec3 normal, CellFrame frame) {
  float c = dot3(normal, frame.centre), w = frame.halfWidth;
  float straddling = (c + w) * (c + w) * frame.rampScale;
  return c >= w ? c : c > -w ? straddling : 0.0f;
}

// f's mass at cell c: its plain mass times ρ and cos, each averaged over the cell's light.
MA_FN float cellIntegrand(PixelCell cell, PhongParams b, MaVec3 normal, MaVec3 mirror) {
  return cell.plain * phongBrdf(b, cellLobe(b, cell.light, mirror)) * cellCosine(normal, cell.light);
}

// A cell's f, p_ρ and plain masses; a chunk's sums of them, its cells added in
// increasing order.
typedef struct {
  float f, q, plain;
} CellMasses;

// Pass 1, any cell in any order: f and p_ρ's mass at cell c.
MA_FN CellMasses pixelCellMasses(MA_GLOBAL const float* cells, int count, int c, PhongParams b, MaVec3 normal,
                                 MaVec3 mirror) {
  PixelCell cell = pixelCellAt(cells, count, c);
  CellMasses m;
  m.f = cellIntegrand(cell, b, normal, mirror);
  m.q = cell.solidAngle * brdfPdfOf(b, cellCosine(normal, cell.area), cellLobe(b, cell.area, mirror));
  m.plain = cell.plain;
  return m;
}

// Kept in the rows for the passes after it.
MA_FN void pixelOptimalCellTerms(MA_GLOBAL const float* cells, int count, int c, PhongParams b, MaVec3 normal,
                                 MaVec3 mirror, MA_LOCAL int* rows, int stride) {
  CellMasses m = pixelCellMasses(cells, count, c, b, normal, mirror);
  setRowFloat(rows, stride, MA_F_ROW(count, c), m.f);
  setRowFloat(rows, stride, MA_BRDF_ROW(count, c), m.q);
}

MA_FN CellMasses storedCellMasses(MA_GLOBAL const float* cells, int count, int c, MA_LOCAL const int* rows,
                                  int stride) {
  CellMasses m;
  m.f = rowFloat(rows, stride, MA_F_ROW(count, c));
  m.q = rowFloat(rows, stride, MA_BRDF_ROW(count, c));
  m.plain = cellField(cells, count, c, CELL_PLAIN);
  return m;
}

// Passes 2 and 3, after pass 1 (whose loop then has no sum, and a compiler may
// vectorise it), add each chunk's f, p_ρ, plain and eq. 6 masses into its rows. They
// run over the cells in order, first the K cells 0 … K − 1 (one of each chunk), then
// K … 2K − 1, …: each chunk's sum adds its cells as a loop over the chunk would, and
// the K sums of a turn lie side by side, so that a compiler may vectorise across them.
MA_FN void zeroChunkSums(int count, MA_LOCAL int* rows, int stride) {
  for (int r = MA_CHUNK_ROW(count, 0, 0); r < MA_CHUNK_ROW(count, CHUNK_SUMS, 0); ++r)
    setRowFloat(rows, stride, r, 0.0f);
}

// The chunks that cells first … first + K − 1 hold.
MA_FN int chunksFrom(int count, int first) { return count - first < MA_PIXEL_CHUNKS ? count - first : MA_PIXEL_CHUNKS; }

MA_FN void addToChunkSums(int count, int j, CellMasses m, MA_LOCAL int* rows, int stride) {
  addToRowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_F, j), m.f);
  addToRowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_BRDF, j), m.q);
  addToRowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_PLAIN, j), m.plain);
}

MA_FN float chunkTotal(MA_LOCAL const int* rows, int stride, int count, int sum) {
  float total = 0.0f;
  for (int j = 0; j < MA_PIXEL_CHUNKS; ++j) total += rowFloat(rows, stride, MA_CHUNK_ROW(count, sum, j));
  return total;
}

// Eq. 6's terms max(0, f/F − (1−C) p_ρ/B), C clamped to [0, 1].
typedef struct {
  float invF, brdfScale;
  int lit;  // F > 0: else the table is the plain pdf's
} PixelOptimalTerms;

MA_FN PixelOptimalTerms pixelOptimalTerms(MA_LOCAL const int* rows, int stride, int count, float envmapShare) {
  float F = chunkTotal(rows, stride, count, CHUNK_F), B = chunkTotal(rows, stride, count, CHUNK_BRDF);
  float C = ma_min(ma_max(envmapShare, 0.0f), 1.0f);
  PixelOptimalTerms t;
  t.lit = F > 0.0f && F < INFINITY;
  t.invF = t.lit ? 1.0f / F : 0.0f;
  t.brdfScale = B > 0.0f && B < INFINITY ? (1.0f - C) / B : 0.0f;
  return t;
}

// [Kar19] eq. 6 before normalisation, over a cell of f and p_ρ masses. Eq. 6 is
// pointwise, and max(0, f/F − (1−C) p_ρ/B) of the cell's masses clips a sun with the
// sky around it where BRDF sampling covers the sky. With f spread as the cell's light
// and p_ρ evenly, f/F − (1−C) p_ρ/B over any set of the cell's texels bounds the cell's
// integral of eq. 6 from below: over the whole cell, and over its peak, ℓ f/F − a (1−C)
// p_ρ/B. The larger is the closer. The peak's is written from the whole's, ℓ ·
// whole + (ℓ − a) · b: two like products here, in the search's three shares unrolled,
// would be paired into short vectors (docs/pocl.md, rule 8), and so would a max().
MA_FN float eq6Value(float f, float q, float peakLight, float peakGap, PixelOptimalTerms t) {
  float b = t.brdfScale * q, whole = f * t.invF - b;
  float peak = ma_fma(peakGap, b, peakLight * whole);
  float v = whole > peak ? whole : peak;
  return v > 0.0f ? v : 0.0f;
}

// Cell c's eq. 6 term, given its f and p_ρ masses.
MA_FN float cellEq6(MA_GLOBAL const float* cells, int count, int c, float f, float q, PixelOptimalTerms t) {
  return eq6Value(f, q, cellField(cells, count, c, CELL_PEAK_LIGHT), cellField(cells, count, c, CELL_PEAK_GAP), t);
}

MA_FN float eq6Term(MA_GLOBAL const float* cells, MA_LOCAL const int* rows, int stride, int count, int c,
                    PixelOptimalTerms t) {
  return cellEq6(cells, count, c, rowFloat(rows, stride, MA_F_ROW(count, c)),
                 rowFloat(rows, stride, MA_BRDF_ROW(count, c)), t);
}

// Pass 3: eq. 6's term added to its chunk's sum.
MA_FN void addToChunkEq6(int count, int j, float term, MA_LOCAL int* rows, int stride) {
  addToRowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_EQ6, j), term);
}

// The table: (1 − d) eq. 6 / Σ eq. 6 + d plain / Σ plain, or the plain pdf alone where
// the BRDF sees no light.
typedef struct {
  float optimal, plain;
} PixelTableScales;

// The scales, given eq. 6's mass and the plain mass over all cells. d is 0 where the
// stage draws BRDF samples (brdfCovers), which cover what eq. 6 clips ([Kar19] Sec. 4),
// and what the product's cells miss: a plain share there only adds variance
// (docs/results.md, "No plain share beside BRDF sampling").
MA_FN PixelTableScales tableScalesOf(PixelOptimalTerms t, float mass, float plain, int brdfCovers) {
  float defensive = brdfCovers ? 0.0f : MA_PIXEL_PLAIN_SHARE;
  float optimalShare = t.lit && mass > 0.0f ? 1.0f - defensive : 0.0f;
  PixelTableScales s;
  s.optimal = optimalShare > 0.0f ? optimalShare / mass : 0.0f;
  s.plain = plain > 0.0f ? (1.0f - optimalShare) / plain : 0.0f;
  return s;
}

MA_FN PixelTableScales pixelTableScales(MA_LOCAL const int* rows, int stride, int count, PixelOptimalTerms t,
                                        int brdfCovers) {
  return tableScalesOf(t, chunkTotal(rows, stride, count, CHUNK_EQ6), chunkTotal(rows, stride, count, CHUNK_PLAIN),
                       brdfCovers);
}

// A cell's mass in the table, from its eq. 6 term and its plain mass.
MA_FN float cellTableMass(PixelTableScales s, float eq6, float plain) { return s.optimal * eq6 + s.plain * plain; }

// A chunk's eq. 6 mass: pass 3's sum, or the product's (t.brdfScale = 0) Σ f times 1/F.
MA_FN float chunkEq6Mass(MA_LOCAL const int* rows, int stride, int count, int j, PixelOptimalTerms t, int product) {
  return product ? rowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_F, j)) * t.invF
                 : rowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_EQ6, j));
}

MA_FN float chunkTableMass(MA_LOCAL const int* rows, int stride, int count, int j, PixelOptimalTerms t,
                           PixelTableScales s, int product) {
  return cellTableMass(s, chunkEq6Mass(rows, stride, count, j, t, product),
                       rowFloat(rows, stride, MA_CHUNK_ROW(count, CHUNK_PLAIN, j)));
}

// The product technique's terms and scales: eq. 6 at C = 1, its mass Σ f/F.
MA_FN PixelOptimalTerms productTerms(MA_LOCAL const int* rows, int stride, int count) {
  return pixelOptimalTerms(rows, stride, count, 1.0f);
}

MA_FN PixelTableScales productTableScales(MA_LOCAL const int* rows, int stride, int count, PixelOptimalTerms t,
                                          int brdfCovers) {
  float mass = 0.0f;
  for (int j = 0; j < MA_PIXEL_CHUNKS; ++j) mass += chunkEq6Mass(rows, stride, count, j, t, 1);
  return tableScalesOf(t, mass, chunkTotal(rows, stride, count, CHUNK_PLAIN), brdfCovers);
}

// Pass 4, per chunk: its CDF entries ⌈offset + partial sum⌉ on uniformFloat's grid, the
// offset the table mass of the chunks before it, each entry at most the next chunk's
// ⌈offset⌉: the CDF never falls across a chunk's edge, however the sums round. The last
// entry is 1. The envmap's CDF, or the product's (product). A chunk's running
// state is plain floats, no struct: a struct of floats carried by a loop is a short
// vector, which keeps PoCL's loop scalar (docs/pocl.md, rule 11).
//
// The entry after the cell at CDF position p, given its chunk's offset, next and
// partial sum up to that cell.
MA_FN float chunkCdfEntry(int count, int p, float offset, float partial, float next) {
  return p + 1 < count ? ma_min(ceilToUniformGrid(ma_min(offset + partial, 1.0f)), next) : 1.0f;
}

MA_FN int cdfFirstRow(int count, int product) { return product ? MA_PRODUCT_CDF_ROW(count, 0) : MA_CDF_ROW(0); }

MA_FN int cdfEntryRow(int count, int p, int product) { return cdfFirstRow(count, product) + p + 1; }

// Where pass 4 keeps each cell's partial sum, in the cells' order: the envmap table's in
// the rows of the cells' f, which nothing reads after them; the product's, built
// first, in the rows of the envmap's CDF, which is written after them.
MA_FN int cellMassRow(int count, int c, int product) { return product ? MA_CDF_ROW(c) : MA_F_ROW(count, c); }

// Pass 4a, over the cells in turns of one cell of each chunk, as passes 2 and 3 run,
// so that a compiler may vectorise across the chunks: each cell's table mass, added to
// its chunk's partial sum, which is kept in place of the mass. Each chunk's sum adds
// its cells in increasing order, as a loop over the chunk would.
MA_FN void pixelOptimalPartialSums(MA_GLOBAL const float* cells, int count, PixelOptimalTerms t, PixelTableScales s,
                                   int product, MA_LOCAL int* rows, int stride) {
  float partial[MA_PIXEL_CHUNKS];
  for (int j = 0; j < MA_PIXEL_CHUNKS; ++j) partial[j] = 0.0f;
  for (int first = 0; first < count; first += MA_PIXEL_CHUNKS)
    MA_CELL_LOOP
    for (int j = 0; j < chunksFrom(count, first); ++j) {
      int c = first + j;
      partial[j] += cellTableMass(s, eq6Term(cells, rows, stride, count, c, t), cellField(cells, count, c, CELL_PLAIN));
      setRowFloat(rows, stride, cellMassRow(count, c, product), partial[j]);
    }
}

// Pass 4b, per chunk: its entries from the partial sums of its cells, which a compiler
// may vectorise.
MA_FN void chunkCdfEntries(int count, int j, float offset, float next, int product, MA_LOCAL int* rows, int stride) {
  int first = chunkStart(count, j), length = chunkLength(count, j), row = cdfEntryRow(count, first, product);
  MA_CELL_GATHER_LOOP
  for (int i = 0; i < length; ++i) {
    float partial = rowFloat(rows, stride, cellMassRow(count, i * MA_PIXEL_CHUNKS + j, product));
    setRowFloat(rows, stride, row + i, chunkCdfEntry(count, first + i, offset, partial, next));
  }
}

// The whole of pass 4: the offset of chunk j is the sum of the chunks' table masses
// before it, added in order.
MA_FN void pixelOptimalCdf(MA_GLOBAL const float* cells, int count, PixelOptimalTerms t, PixelTableScales s,
                           int product, MA_LOCAL int* rows, int stride) {
  pixelOptimalPartialSums(cells, count, t, s, product, rows, stride);
  float offset = 0.0f;
  for (int j = 0; j < MA_PIXEL_CHUNKS; ++j) {
    float end = offset + chunkTableMass(rows, stride, count, j, t, s, product);
    chunkCdfEntries(count, j, offset, ceilToUniformGrid(ma_min(end, 1.0f)), product, rows, stride);
    offset = end;
  }
  setRowFloat(rows, stride, cdfFirstRow(count, product), 0.0f);
}

// The share columns' share s of MA_MAX_BANK_SHARES: C_s = (s+1)/(shares+1), the bank's
// (bankShareOf, kernels/envmap.h).
MA_FN float columnShare(int s) { return (float)(s + 1) / (float)(MA_MAX_BANK_SHARES + 1); }

// Eq. 6's mass under terms t, summed as pass 3 sums it (chunk by chunk, then over the
// chunks): the same bits as the stage's own where C is the same. Its chunks' sums go to
// the CDF's first rows, which pass 4 writes later; each cell's term to share s's mass
// rows, which pixelShareMasses scales. A sum over the cells in order is one chain of
// dependent additions, which a lane's own build (samplePixelStage: vectorised over the
// cells, not across pixels) cannot overlap.
MA_FN float eq6MassByChunks(MA_GLOBAL const float* cells, int count, PixelOptimalTerms t, int s, MA_LOCAL int* rows,
                            int stride) {
  int chunks = count < MA_PIXEL_CHUNKS ? count : MA_PIXEL_CHUNKS;
  for (int j = 0; j < chunks; ++j) setRowFloat(rows, stride, MA_CDF_ROW(j), 0.0f);
  for (int first = 0; first < count; first += MA_PIXEL_CHUNKS)
    for (int j = 0; j < chunksFrom(count, first); ++j) {
      float term = eq6Term(cells, rows, stride, count, first + j, t);
      setRowFloat(rows, stride, MA_SHARE_MASS_ROW(count, s, first + j), term);
      addToRowFloat(rows, stride, MA_CDF_ROW(j), term);
    }
  float mass = 0.0f;
  for (int j = 0; j < chunks; ++j) mass += rowFloat(rows, stride, MA_CDF_ROW(j));
  return mass;
}

// Share s's table's mass in each cell, from its eq. 6 terms in place: each stored
// sample's pdf under the share then reads one row, where taking the cell's f again
// per sample (its frame's lobe, a gather of the cell's fields) made exact's pilot 4–5×
// as slow per sample as a stage without share columns (docs/results.md, "The share
// columns' masses kept per cell").
MA_FN void pixelShareMasses(MA_GLOBAL const float* cells, int count, int s, PixelTableScales scales, MA_LOCAL int* rows,
                            int stride) {
  MA_CELL_LOOP
  for (int c = 0; c < count; ++c) {
    int row = MA_SHARE_MASS_ROW(count, s, c);
    setRowFloat(rows, stride, row,
                cellTableMass(scales, rowFloat(rows, stride, row), cellField(cells, count, c, CELL_PLAIN)));
  }
}

// Pass 3b, for the share columns, while the rows hold each cell's f: every share's
// table's mass in each cell, from the table's scales. Only the search reads them.
MA_FN void pixelOptimalShareMasses(MA_GLOBAL const float* cells, int count, MA_LOCAL int* rows, int stride) {
  float plain = chunkTotal(rows, stride, count, CHUNK_PLAIN);
  for (int s = 0; s < MA_MAX_BANK_SHARES; ++s) {
    PixelOptimalTerms t = pixelOptimalTerms(rows, stride, count, columnShare(s));
    // A stage of share C_s < 1 draws BRDF samples.
    PixelTableScales scales = tableScalesOf(t, eq6MassByChunks(cells, count, t, s, rows, stride), plain, 1);
    pixelShareMasses(cells, count, s, scales, rows, stride);
  }
}

// The product technique's terms and table scales (eq. 6 at C = 1).
typedef struct {
  PixelOptimalTerms t;
  PixelTableScales s;
} ProductCdfTerms;

MA_FN ProductCdfTerms productCdfTerms(MA_LOCAL const int* rows, int stride, int count, int brdfCovers) {
  ProductCdfTerms p;
  p.t = productTerms(rows, stride, count);
  p.s = productTableScales(rows, stride, count, p.t, brdfCovers);
  return p;
}

// The whole build by one work-item (the C++ reference): the pixel's CDF over `count`
// cells at rows[r · stride], r = 0 … count, for a stage of envmap share C that draws
// BRDF samples or not (brdfCovers, stageDrawsBrdf); with `shareColumns`, the share
// columns' scales too; with `productCdf`, the product's CDF. Both kernels call it, one
// pixel a work-item.
MA_FN void buildPixelOptimalCdf(MA_GLOBAL const float* cells, int count, PhongParams b, MaVec3 normal, MaVec3 mirror,
                                float envmapShare, int brdfCovers, int shareColumns, int productCdf, MA_LOCAL int* rows,
                                int stride) {
  MA_CELL_LOOP
  for (int c = 0; c < count; ++c) pixelOptimalCellTerms(cells, count, c, b, normal, mirror, rows, stride);
  zeroChunkSums(count, rows, stride);
  for (int first = 0; first < count; first += MA_PIXEL_CHUNKS)
    MA_CELL_LOOP
    for (int j = 0; j < chunksFrom(count, first); ++j)
      addToChunkSums(count, j, storedCellMasses(cells, count, first + j, rows, stride), rows, stride);
  PixelOptimalTerms t = pixelOptimalTerms(rows, stride, count, envmapShare);
  for (int first = 0; first < count; first += MA_PIXEL_CHUNKS)
    MA_CELL_LOOP
    for (int j = 0; j < chunksFrom(count, first); ++j)
      addToChunkEq6(count, j, eq6Term(cells, rows, stride, count, first + j, t), rows, stride);
  if (shareColumns) pixelOptimalShareMasses(cells, count, rows, stride);
  PixelTableScales s = pixelTableScales(rows, stride, count, t, brdfCovers);
  if (productCdf) {
    ProductCdfTerms p = productCdfTerms(rows, stride, count, brdfCovers);
    pixelOptimalCdf(cells, count, p.t, p.s, 1, rows, stride);
  }
  pixelOptimalCdf(cells, count, t, s, 0, rows, stride);
}

// The product technique's view of the pixel's cells: the envmap's, over the product's CDF.
MA_FN EnvmapView pixelProductView(EnvmapView env) {
  env.pixelCdf += MA_PRODUCT_CDF_ROW(env.pixelCells, 0) * env.pixelCdfStride;
  return env;
}

// The envmap's pdf at ω in texel t under the table of each share (stats.h's share
// columns), from the cell's masses pass 3b kept.
MA_FN void pixelSharePdfs(EnvmapView env, int t, float sinTheta, float* pdfs) {
  MA_LOCAL const int* rows = env.pixelCdf;
  int count = env.pixelCells, stride = env.pixelCdfStride, c = blockOfTexel(env, t);
  float inCell = env.texels[4 * t + 3];
  MA_UNROLL
  for (int s = 0; s < MA_MAX_BANK_SHARES; ++s)
    pdfs[s] = envmapPdfOfTexel(env, inCell * rowFloat(rows, stride, MA_SHARE_MASS_ROW(count, s, c)), sinTheta);
}

#endif
