// The product technique ([CL18]): envmap × BRDF × cos, tabulated over blocks of texels.
// Every pixel sees the map from the same normal and view, so its product differs from
// another's only by its BRDF's two lobes: the product's table over blocks is the mixture
// of a diffuse table (L cos) and a specular one (L cos^n α cos, for the pixel's exponent
// bin), weighted by the pixel's own ρd, ρs and n, and of the plain envmap's table, which
// keeps the pdf positive wherever the map is lit. A block is drawn from the table, then
// a texel in it by its luminance × sin θ, as the optimal pdf's bank does (kernels/envmap.h):
// the full resolution stays. Host side: host/distributions/ProductTables.h builds the
// tables; the technique is technique 2 of kernels/estimator.h (`--product`).
//
// With the optimal pdf per pixel, whose pixels may each see the map from their own normal
// and view, the product comes instead from the pixel's own cells (ProductView::pixelCells,
// kernels/pixel_optimal.h): no table at all.
#include "namespace_check.h"
#ifndef MA_PRODUCT_H
#define MA_PRODUCT_H
#include "common.h"
#include "envmap.h"
#include "phong.h"
#include "pixel_optimal.h"

// Tables: 0 the plain envmap's blocks, 1 the diffuse product, 2 + i the specular product
// of exponent bin i's table. A pixel's exponent bin splits each octave of n + 1 at 1.5×;
// bins past the last hold every larger exponent.
#define MA_PRODUCT_TABLE_PLAIN 0
#define MA_PRODUCT_TABLE_DIFFUSE 1
#define MA_PRODUCT_EXPONENT_BINS 36  // n + 1 < 2^18, even: the words after it stay 8-byte aligned
// The plain envmap's share of every pixel's mixture: the defensive part that keeps the
// pdf positive where the lobes' tables, taken at cell centres, are 0 (a lobe narrower
// than a cell, a cell below the horizon whose block is not).
#define MA_PRODUCT_PLAIN_SHARE 0.125f

// The buffers of host/distributions/ProductTables.h. floats: per table its lobe integral
// (∫ L × lobe × cos, unnormalised), then per table and block the ratio of the table's
// block probability to the plain envmap's (0 where the block is black), then per texel
// its plain probability (luminance × sin θ over the map's total). words: per exponent bin
// its table, then per table and block the alias table over blocks, then per block and
// slot the alias table over the block's slots. The product's probability of texel t in
// block B is then Σ_k m_k r_k(B) × the plain probability of t.
typedef struct {
  MA_GLOBAL const float* floats;
  MA_GLOBAL const ma_uint* words;
  int tables;       // 0: no tables (no product technique, or the pixel's cells')
  int blockLog2;    // blocks of 2^L × 2^L texels
  int plainTexels;  // 1: the envmap's own pdf is the plain one, so the product scales it
  int pixelCells;   // 1: the product is the pixel's CDF over the optimal pdf's cells
} ProductView;

// Whether technique 2 is the product technique.
MA_FN int productEnabled(ProductView p) { return p.tables > 0 || p.pixelCells; }

MA_FN int productBlocksAcross(EnvmapView env, ProductView p) {
  return (env.width + (1 << p.blockLog2) - 1) >> p.blockLog2;
}
MA_FN int productBlocks(EnvmapView env, ProductView p) {
  return productBlocksAcross(env, p) * ((env.height + (1 << p.blockLog2) - 1) >> p.blockLog2);
}

// n + 1's octave and half-octave from its float bits: the same bin on host and device.
MA_FN int productExponentBin(float n) {
  int bin = (int)(ma_as_uint(n + 1.0f) >> 22) - (127 << 1);
  return bin < 0 ? 0 : (bin >= MA_PRODUCT_EXPONENT_BINS ? MA_PRODUCT_EXPONENT_BINS - 1 : bin);
}

// The pixel's mixture of the tables: diffuse with probability `diffuse`, its specular
// table with `specular`, the plain envmap's with the rest.
typedef struct {
  float diffuse, specular;
  int specularTable;
} ProductMixture;

// The lobes in proportion to their integrals against the map: ρd/π ∫ L cos and
// ρs (n+2)/(2π) ∫ L cos^n α cos ([HS14] eq. 6.13), the latter tabulated for the bin's
// exponent. A BRDF that sees no light takes the plain envmap's table alone. Once per
// pixel: the sampling kernel keeps it in the pixel's rows (kernels/sample.cl).
MA_FN ProductMixture productMixture(ProductView p, PhongParams b) {
  ProductMixture m;
  m.specularTable = (int)p.words[productExponentBin(b.n)];
  float diffuse = b.rhoD * MA_INV_PI * p.floats[MA_PRODUCT_TABLE_DIFFUSE];
  float specular = b.rhoS * (b.n + 2.0f) * (0.5f * MA_INV_PI) * p.floats[m.specularTable];
  float total = diffuse + specular;
  int lit = total > 0.0f && total < INFINITY;
  float lobes = 1.0f - MA_PRODUCT_PLAIN_SHARE;
  m.diffuse = lit ? ceilToUniformGrid(lobes * (diffuse / total)) : 0.0f;
  float both = lit ? ceilToUniformGrid(lobes) : 0.0f;
  m.specular = ma_max(both - m.diffuse, 0.0f);
  return m;
}

// The pixel's product over the plain envmap pdf in block B: Σ_k m_k r_k(B).
MA_FN float productRatio(EnvmapView env, ProductView p, ProductMixture m, int block) {
  MA_GLOBAL const float* ratios = p.floats + p.tables;
  int blocks = productBlocks(env, p);
  float plain = 1.0f - m.diffuse - m.specular;
  return ma_fma(m.diffuse, ratios[MA_PRODUCT_TABLE_DIFFUSE * blocks + block],
                ma_fma(m.specular, ratios[m.specularTable * blocks + block], plain));
}

// The product's solid-angle pdf at ω in texel t for the pixel's mixture: the plain
// envmap pdf there (plainPdf where the envmap's own pdf is plain, ProductView::plainTexels;
// else from the texel's plain probability and ω's sinTheta) times productRatio. From the
// pixel's cells: the texel's probability in its cell times the cell's in the product's CDF.
MA_FN float productPdf(EnvmapView env, ProductView p, ProductMixture m, int t, float plainPdf, float sinTheta) {
  if (p.pixelCells) return envmapPdfOfTexel(env, texelProbability(pixelProductView(env), t), sinTheta);
  int row = rowOfIndex(t, env.width), col = t - row * env.width;
  int block = (row >> p.blockLog2) * productBlocksAcross(env, p) + (col >> p.blockLog2);
  float plain = p.plainTexels
                    ? plainPdf
                    : envmapPdfOfTexel(env, p.floats[p.tables + p.tables * productBlocks(env, p) + t], sinTheta);
  return productRatio(env, p, m, block) * plain;
}

// A direction from the pixel's product: the table by `mixtureU`, its block by rnd.v[0]
// and v[1], the texel in the block and the jitter by v[2] and v[3] (sampleTexelInBlock);
// from the pixel's cells, as the envmap's cells draw (sampleEnvmapPixelCells).
MA_FN EnvmapSample sampleProduct(EnvmapView env, ProductView p, ProductMixture m, MaRandom4 rnd, float mixtureU) {
  if (p.pixelCells) return sampleEnvmapPixelCells(pixelProductView(env), rnd);
  int table = mixtureU < m.diffuse ? MA_PRODUCT_TABLE_DIFFUSE
                                   : (mixtureU < m.diffuse + m.specular ? m.specularTable : MA_PRODUCT_TABLE_PLAIN);
  int blocks = productBlocks(env, p);
  MA_GLOBAL const ma_uint* blockTables = p.words + MA_PRODUCT_EXPONENT_BINS;
  int block = sampleAliasTable(blockTables + 2 * table * blocks, (ma_uint)blocks, rnd.v[0], uniformFloat(rnd.v[1]));
  return sampleTexelInBlock(env, blockTables + 2 * p.tables * blocks, block, productBlocksAcross(env, p), p.blockLog2,
                            rnd);
}

#endif
