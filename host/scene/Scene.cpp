#include "scene/Scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "Error.h"
#include "KernelCode.h"
#include "distributions/BankCache.h"
#include "scene/SceneShape.h"
#include "scene/Surfaces.h"

namespace misalloc {
namespace fs = std::filesystem;

bool SceneOptions::perPixelGeometry() const {
  return !gbuffer.path.empty() || !mesh.path.empty() || parseSceneShape(shape).kind != SceneShape::Plane;
}

EnvmapPdf defaultEnvmapPdf(const SceneOptions& options) {
  if (options.splitBrdf) return {};
  // The bank is built for one normal and view; per-pixel geometry builds its own tables
  // (docs/results.md, "The optimal pdf per pixel").
  return parseEnvmapPdf(options.perPixelGeometry() ? "optimal-pixel" : "optimal");
}

int SceneOptions::techniqueRole(int technique) const { return kern::techniqueRole(splitBrdf, product, technique); }

const char* techniqueRoleName(int role) {
  static const char* const names[kern::ROLE_COUNT] = {"envmap", "brdf", "diffuse", "specular", "product"};
  return names[role];
}

std::vector<std::string> Scene::techniqueNames() const {
  std::vector<std::string> names;
  for (int k = 0; k < techniqueCount(); ++k) names.push_back(techniqueRoleName(options.techniqueRole(k)));
  return names;
}

namespace {

// Where shipped data of `kind` (envmaps, meshes) is looked for, in order.
std::vector<std::string> dataDirs(const std::string& kind) {
  std::vector<std::string> dirs;
  if (const char* env = std::getenv("MISALLOC_DATA_DIR")) dirs.push_back(fmt::format("{}/{}", env, kind));
  dirs.push_back(MISALLOC_INSTALL_DATA_DIR "/" + kind);
  dirs.push_back(MISALLOC_SOURCE_DIR "/data/" + kind);
  return dirs;
}

std::vector<std::string> envmapDirs() { return dataDirs("envmaps"); }

}  // namespace

std::vector<std::string> shippedEnvmapNames() {
  for (const auto& dir : envmapDirs()) {
    if (!fs::is_directory(dir)) continue;
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir))
      if (entry.path().extension() == ".exr") names.push_back(entry.path().stem().string());
    if (names.empty()) continue;
    std::sort(names.begin(), names.end());
    return names;
  }
  throw InputError(fmt::format("no shipped envmaps in {}", fmt::join(envmapDirs(), ", ")));
}

std::string resolveEnvmapSpec(const std::string& spec) {
  for (const char* procedural : {"constant", "cosk", "sun"})
    if (spec == procedural || spec.rfind(std::string(procedural) + ":", 0) == 0) return spec;
  if (fs::exists(spec) || spec.find('/') != std::string::npos || spec.find(".exr") != std::string::npos) return spec;
  const std::vector<std::string> dirs = envmapDirs();
  for (const auto& dir : dirs) {
    fs::path candidate = fs::path(dir) / (spec + ".exr");
    if (fs::exists(candidate)) return candidate.string();
  }
  throw InputError(
      fmt::format("--envmap '{}': no such file, and no shipped map of that name in {}", spec, fmt::join(dirs, ", ")));
}

std::string resolveMeshSpec(const std::string& spec) {
  if (spec.empty() || fs::exists(spec) || spec.find('/') != std::string::npos || spec.find('.') != std::string::npos)
    return spec;
  const std::vector<std::string> dirs = dataDirs("meshes");
  for (const auto& dir : dirs) {
    fs::path candidate = fs::path(dir) / (spec + ".obj");
    if (fs::exists(candidate)) return candidate.string();
  }
  throw InputError(
      fmt::format("--mesh '{}': no such file, and no shipped mesh of that name in {}", spec, fmt::join(dirs, ", ")));
}

EnvmapSampler parseEnvmapSampler(const std::string& name) {
  if (name == "alias") return EnvmapSampler::Alias;
  if (name == "cdf") return EnvmapSampler::Cdf;
  throw InputError(fmt::format("--envmap-sampler '{}': expected alias or cdf", name));
}

const Vec3f& flatMirror(const SceneGeometry& geometry, const std::string& option) {
  if (!geometry.flat())
    throw InputError(fmt::format(
        "{} with per-pixel normals or views: not implemented; its tables are built for one normal and view", option));
  return geometry.pixels.front().mirror;
}

void leaveOutBackground(const Scene& scene, std::vector<int32_t>& counts) {
  const int M = scene.techniqueCount();
  const std::vector<unsigned char>& covered = scene.geometry.covered;
  for (size_t p = 0; p < covered.size(); ++p)
    if (!covered[p]) std::fill_n(counts.begin() + ptrdiff_t(p * M), M, 0);
}

Scene makeScene(const SceneOptions& options) {
  if (options.product && options.splitBrdf)
    throw InputError(
        "--product with --split-brdf: not implemented; the kernels take at most 3 techniques (MA_MAX_TECHNIQUES), "
        "and the BRDF's lobes split and the product make 4");
  Scene scene;
  scene.options = options;
  if (!options.mesh.path.empty()) {
    if (options.shape != "plane" || !options.gbuffer.path.empty())
      throw InputError("--mesh with --scene or --gbuffer: the mesh is the scene; drop one");
    GBufferImage seen = rasteriseMesh(options.mesh, options.gbuffer, options.width, options.height);
    scene.grid = makeBrdfGrid(options.grid, options.width, options.height);
    scene.geometry = std::move(seen.geometry);
  } else if (!options.gbuffer.path.empty()) {
    if (options.shape != "plane") throw InputError("--gbuffer with --scene: the G-buffer is the scene; drop one");
    GBufferImage gbuffer = readGBuffer(options.gbuffer);
    scene.options.width = gbuffer.width;
    scene.options.height = gbuffer.height;
    if (!gbuffer.brdf.empty())
      scene.grid = BrdfGrid{gbuffer.brdfSpec, gbuffer.width, gbuffer.height, std::move(gbuffer.brdf)};
    else if (!gbuffer.uv.empty())
      scene.grid = makeBrdfGrid(options.grid, gbuffer.width, gbuffer.height, gbuffer.uv);
    else
      scene.grid = makeBrdfGrid(options.grid, gbuffer.width, gbuffer.height);
    scene.geometry = std::move(gbuffer.geometry);
  } else {
    ShapeImage shape =
        shapeImage(parseSceneShape(options.shape), options.width, options.height, options.viewTheta, options.viewPhi);
    scene.grid = makeBrdfGrid(options.grid, options.width, options.height, shape.uv);
    scene.geometry = std::move(shape.geometry);
  }
  scene.surfaces = labelSurfaces(scene.geometry, scene.grid);
  if (options.envmapTexels) {
    scene.envmap = envmapFromTexels(*options.envmapTexels, options.envmap, &scene.envmapWarnings);
  } else {
    std::string resolved = resolveEnvmapSpec(options.envmap);
    if (resolved != options.envmap || fs::exists(resolved)) scene.envmapPath = resolved;
    scene.envmap = makeEnvmap(resolved, options.proceduralWidth, &scene.envmapWarnings);
  }
  if (options.envmapPdf.optimal()) {
    // q = (1−C) p_ρ of [Kar19] eq. 9 takes the BRDF as one technique; split into lobes,
    // q would depend on the lobes' shares too.
    if (options.splitBrdf)
      throw InputError(
          "--envmap-pdf optimal with --split-brdf: not implemented; the optimal pdf's bank is built "
          "for the BRDF as one technique (M = 2)");
    const Vec3f& mirror = flatMirror(scene.geometry, "--envmap-pdf optimal");
    std::optional<EnvmapTables> cached;
    if (!options.bankCacheDir.empty()) {
      const auto start = std::chrono::steady_clock::now();
      scene.bankCacheKey = bankCacheKey(scene.envmap, options.sampler, scene.grid, mirror);
      cached = readCachedBank(options.bankCacheDir, scene.bankCacheKey, scene.envmap.image);
      // A hit costs its key (every texel hashed) and its read.
      if (cached)
        cached->bankBuildSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    scene.tables =
        cached ? std::move(*cached) : buildOptimalEnvmapTables(scene.envmap, options.sampler, scene.grid, mirror);
  } else if (options.envmapPdf.pixelOptimal()) {
    if (options.splitBrdf)
      throw InputError(
          "--envmap-pdf optimal-pixel with --split-brdf: not implemented; eq. 9's q takes the BRDF as one "
          "technique (M = 2)");
    // Its own sampler whatever --envmap-sampler says: a cell by the pixel's CDF, a texel
    // in it by the cell's alias table.
    const EnvmapPdf& pdf = options.envmapPdf;
    scene.tables = buildPixelOptimalEnvmapTables(scene.envmap, pdf.cellsAcross);
    // The tables know their own cells; the pilot's, which the report names, are the scene's.
    scene.tables.requestedPdf.pilotCellsAcross = pdf.pilotCellsAcross;
    if (scene.tables.pdf.pixelOptimal()) scene.tables.pdf.pilotCellsAcross = pdf.pilotCellsAcross;
    const int pilotLog2 = pixelCellLog2(scene.envmap.image.width, scene.envmap.image.height, pdf.pilotCellsAcross);
    if (scene.tables.pixelCells > 0 && pilotLog2 != scene.tables.blockLog2)
      scene.pilotTables = buildPixelOptimalEnvmapTables(scene.envmap, pdf.pilotCellsAcross);
  } else {
    scene.tables = buildEnvmapTables(scene.envmap, options.sampler, options.envmapPdf);
  }
  if (options.product && scene.tables.pixelCells > 0) {
    // The product from each pixel's own cells, whatever its normal and view.
    scene.productTables.pixelCells = true;
  } else if (options.product) {
    // Under a black map the optimal pdf per pixel falls back to plain, and the product's
    // tables hold the plain envmap's alone (nothing is lit): any normal and view will do.
    const bool black = options.envmapPdf.pixelOptimal();
    if (!black && !scene.geometry.flat())
      throw InputError(fmt::format(
          "--product with --envmap-pdf {} and per-pixel normals or views: not implemented; its tables are built for "
          "one normal and view (with --envmap-pdf optimal-pixel, each pixel builds its own)",
          envmapPdfName(options.envmapPdf)));
    scene.productTables = buildProductTables(scene.envmap, scene.grid,
                                             black ? Vec3f{0.0f, 0.0f, 1.0f} : flatMirror(scene.geometry, "--product"));
    const EnvmapTables& t = scene.tables;
    scene.productTables.plainTexels = t.pdf.plain() && !t.hasBank() && !t.useCdf;
  }
  // The tables hold every texel's RGB beside its probability (kernels/envmap.h), so the
  // input copy goes: 12 of the map's bytes per texel. Any other pdf than plain keeps it
  // for the plain tables of the reference and the costs (withPlainEnvmapPdf).
  if (options.envmapPdf.plain()) scene.envmap.image.rgb = std::vector<float>();
  return scene;
}

void cacheOptimalBank(const Scene& scene) {
  if (!scene.bankCacheKey.empty() && !scene.tables.bankFromCache)
    writeCachedBank(scene.options.bankCacheDir, scene.bankCacheKey, scene.tables);
}

Scene withPlainEnvmapPdf(const Scene& scene) {
  if (scene.options.envmapPdf.plain()) return scene;
  Scene plain = scene;
  plain.options.envmapPdf = {};
  plain.tables = buildEnvmapTables(plain.envmap, plain.options.sampler);
  plain.pilotTables = {};
  return plain;
}

const EnvmapTables& stageTables(const Scene& scene, bool keepsStatistics) {
  return keepsStatistics && scene.pilotTables.pixelCells > 0 ? scene.pilotTables : scene.tables;
}

}  // namespace misalloc
