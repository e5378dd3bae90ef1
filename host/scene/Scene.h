#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "distributions/EnvmapDistribution.h"
#include "distributions/ProductTables.h"
#include "scene/BrdfGrid.h"
#include "scene/Envmap.h"
#include "scene/GBuffer.h"
#include "scene/Mesh.h"
#include "scene/SceneGeometry.h"

namespace misalloc {

struct SceneOptions {
  std::string envmap = "forest_slope";  // a path, a shipped map's name, or a procedural spec
  std::string grid = "seed000";
  std::string shape = "plane";  // --scene (scene/SceneShape.h)
  GBufferOptions gbuffer;       // --gbuffer: each pixel's frame read from a file instead of a shape
  MeshOptions mesh;             // --mesh: a mesh seen from gbuffer.cameraOrigin, in gbuffer.convention's world
  int width = 128, height = 128;
  double viewTheta = 0, viewPhi = 0;  // ω_o in degrees (shapeImage)
  bool splitBrdf = false;             // M = 3: the BRDF's lobes as techniques of their own
  bool product = false;               // M = 3: envmap × BRDF × cos as a third technique (--product)
  EnvmapSampler sampler = EnvmapSampler::Alias;
  EnvmapPdf envmapPdf;  // [Kar19]: plain, or compensated for MIS with BRDF sampling
  int proceduralWidth = 512;
  // Where the optimal pdf's tables are cached (distributions/BankCache.h); empty: built
  // every time. Not part of the scene: the same tables either way.
  std::string bankCacheDir;
  // The map's texels given in memory (the Python module's array); `envmap` then only
  // names it.
  std::shared_ptr<const RgbImage> envmapTexels;

  // M: envmap sampling and BRDF sampling, then either of the BRDF's lobes split, or the
  // product technique.
  int techniqueCount() const { return splitBrdf || product ? 3 : 2; }
  // Whether each pixel has a normal and view of its own (not [HS14]'s plane), for which
  // the optimal pdf and the product technique are not implemented.
  bool perPixelGeometry() const;
  // --product on per-pixel geometry: it comes from the optimal pdf per pixel's cells,
  // the only pdf that allows it there.
  bool productNeedsPixelCells() const { return product && perPixelGeometry(); }

  // What technique k samples: kern::ROLE_ENVMAP, ROLE_BRDF, ... (kernels/estimator.h).
  int techniqueRole(int technique) const;
};

// A role's name, as reports and α maps name the technique: envmap, brdf, diffuse,
// specular, product.
const char* techniqueRoleName(int role);

// Everything the sampling kernel reads, built once per run.
struct Scene {
  SceneOptions options;
  std::string envmapPath;  // the resolved file, empty for procedural maps
  Envmap envmap;           // its image keeps width and height; the texels live in `tables`
  EnvmapTables tables;
  // The optimal pdf per pixel's coarser cells, for the stages that keep statistics
  // (EnvmapPdf::pilotCellsAcross); none (pixelCells 0) where they would be the same.
  EnvmapTables pilotTables;
  ProductTables productTables;  // --product; none otherwise
  BrdfGrid grid;
  SceneGeometry geometry;  // each pixel's normal and mirror direction
  // Per pixel, the surface it shows (labelSurfaces): the pooled allocations pool within
  // one. Labelled on the whole image, so that a band's rows keep the image's labels.
  std::vector<int32_t> surfaces;
  ReadWarnings envmapWarnings;  // negative texels set to 0 on reading
  std::string bankCacheKey;     // where the optimal pdf's tables were looked up in SceneOptions::bankCacheDir
  // The image's index of pixel 0: 0 for a whole image; a band of an image's rows
  // (render/Band.h) keys its random numbers on the image's pixels, so that it draws
  // exactly the samples the whole image's render draws there.
  int firstPixel = 0;

  int techniqueCount() const { return options.techniqueCount(); }
  int pixelCount() const { return grid.width * grid.height; }
  std::vector<std::string> techniqueNames() const;
};

// The one mirror direction of a flat scene, for which the optimal pdf's bank and the
// product tables are built; throws InputError naming `option` for any other geometry.
const Vec3f& flatMirror(const SceneGeometry& geometry, const std::string& option);

// The tables a stage samples from: the pilot's where it keeps statistics and the scene
// has them, else the scene's own. The product's cells are the same (kernels/product.h).
const EnvmapTables& stageTables(const Scene& scene, bool keepsStatistics);

// Counts [pixel·M + k] with the background's set to 0 (SceneGeometry::covered): it takes
// no samples, whatever a method, an allocation or a calibration would give it.
void leaveOutBackground(const Scene& scene, std::vector<int32_t>& counts);

// Builds the scene, reading the optimal pdf's tables from SceneOptions::bankCacheDir
// where they are cached there.
Scene makeScene(const SceneOptions& options);

// Writes the optimal pdf's tables to the cache where makeScene built them: after a run
// has done its work, so that a refused or failed run writes no cache entry.
void cacheOptimalBank(const Scene& scene);

// The envmap pdf of a render that names none: the optimal one ([Kar19] eq. 9), the
// largest gain misalloc has, where it can serve; with the BRDF's lobes split the plain
// one; with per-pixel geometry the compensated one ([Kar19] eq. 14), normal-independent.
EnvmapPdf defaultEnvmapPdf(const SceneOptions& options);

// The scene with the plain envmap pdf, for the reference: the pdf changes the noise,
// not the integral, and a reference computed once must not depend on which pdf asked
// for it first (referenceKey leaves the pdf out).
Scene withPlainEnvmapPdf(const Scene& scene);

// A shipped map's name ("forest_slope") or a path to an EXR; procedural specs
// (constant, cosk:K, sun...) are returned unchanged. Throws InputError naming the
// places searched when a name matches no file.
std::string resolveEnvmapSpec(const std::string& spec);

// The names of the envmaps shipped in data/envmaps (installed or in the source tree),
// sorted.
std::vector<std::string> shippedEnvmapNames();

// A shipped mesh's name ("blob": data/meshes/blob.obj) or a path, returned unchanged.
// Throws InputError naming the places searched when a name matches no file.
std::string resolveMeshSpec(const std::string& spec);

EnvmapSampler parseEnvmapSampler(const std::string& name);

}  // namespace misalloc
