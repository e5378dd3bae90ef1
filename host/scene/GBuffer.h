#pragma once
// G-buffers that renderers write (--gbuffer): each pixel's shading normal, position and
// coverage in the renderer's world, turned into the map's frame (kernels/envmap.h: z up,
// u = atan2(y, x)/2π) by the convention that also orients the renderer's lat-long map, so
// that a G-buffer and a map exported from one renderer are lit as that renderer lights them.
#include <array>
#include <map>
#include <memory>
#include <string>

#include "scene/BrdfGrid.h"
#include "scene/ExrIO.h"
#include "scene/SceneGeometry.h"

namespace misalloc {

enum class GBufferConvention { Misalloc, Mitsuba, Blender, Pbrt };

// "misalloc", "mitsuba", "blender" or "pbrt"; throws InputError naming --convention.
GBufferConvention parseGBufferConvention(const std::string& name);

using Vec3d = std::array<double, 3>;

// A direction of the convention's world in the map's frame: the orthogonal map under which
// misalloc's lookup of the result is the renderer's lookup of the direction.
// Mitsuba 3 (src/emitters/envmap.cpp): d = (sin φ sin θ, cos θ, −cos φ sin θ), φ = 2πu,
// θ = πv, so (x, y, z) → (−z, x, y). Blender: u = (π − atan2(y, x))/2π, top row +z, so
// (x, y, z) → (−x, y, z). pbrt-v4 (imgtool makeequiarea) and misalloc: the identity.
Vec3d toMapFrame(GBufferConvention convention, const Vec3d& d);

// A G-buffer given in memory (the Python module's arrays): what a file's header would say
// (size, channel names, matrices) and one plane per channel, row 0 first.
struct ChannelImage {
  ExrHeader header;
  std::map<std::string, std::vector<float>> planes;
};

struct GBufferOptions {
  std::string path;  // empty: no G-buffer; with `channels`, only their name in messages
  std::string convention = "misalloc";
  // Channel prefixes of .X, .Y, .Z; empty: the convention's (misalloc N, P; Mitsuba
  // sh_normal, position; Blender <ViewLayer>.Normal, <ViewLayer>.Position; pbrt Ns, P).
  std::string normalChannels, positionChannels;
  // "X,Y,Z" in the G-buffer's world: each pixel is seen from there. pbrt's camera space
  // has its camera at the origin and needs none.
  std::string cameraOrigin;
  // "camera" or "world"; empty: the convention's. pbrt-v4 writes camera space unless its
  // scene says `coordinatesystem "world"`; its header's worldToCamera takes the frames to
  // the world. The others write world space.
  std::string space;
  std::shared_ptr<const ChannelImage> channels;  // the G-buffer in memory instead of the file at `path`
  // "X,Y,Z" in the file's space: an orthographic view, every pixel seen from this
  // direction (towards the camera), in place of positions and a camera origin.
  std::string viewDirection;
};

struct GBufferImage {
  int width = 0, height = 0;
  SceneGeometry geometry;
  // The BRDF per pixel where the file holds channels rho_d, rho_s and phong_n or
  // roughness (brdfSpec says which: kGBufferBrdf or kGBufferRoughnessBrdf); else
  // empty, and `uv` where it holds the convention's UV channels (misalloc, Mitsuba uv.U,
  // uv.V; Blender <ViewLayer>.UV.U, .V; pbrt u, v), wrapped into [0, 1), over which
  // --grid is laid; else both empty, and the grid lies over the image.
  std::vector<PhongParameters> brdf;
  std::string brdfSpec;
  std::vector<SurfaceUv> uv;
};

// The Phong exponent of a perceptual roughness r ∈ [0, 1] (a `roughness` channel), as
// Blender's Principled BSDF and Disney's BRDF take r: capped at 10⁵, the largest
// exponent misalloc takes (r → 0).
double phongExponentOfRoughness(double r);

// Each pixel's frame (normal turned to face its view, the mirror direction of the view)
// and coverage; the view from the channels view.X, .Y, .Z (towards the camera) where the
// file has them, or the one direction of an orthographic view (viewDirection), either
// of which then needs neither positions nor a camera; else from the position to the
// camera. Coverage: the alpha channel A where the file has one (> 0: covered), and a zero
// normal marks the background too. Throws InputError before any work on: a missing
// channel (naming those looked for and those found), a NaN or infinite normal or
// position on a covered pixel, a camera origin missing where the convention needs one or
// lying on a covered pixel's surface, a file that covers no pixel, some BRDF channels
// without the others, both phong_n and roughness, a covered pixel's roughness outside
// [0, 1], or its BRDF outside ρd, ρs ≥ 0, ρd + ρs ≤ 1, n ∈ [0, 10⁵].
GBufferImage readGBuffer(const GBufferOptions& options);

// The G-buffer of a scene as misalloc reads it back (--gbuffer, convention misalloc): N,
// view (towards the camera), A, and the BRDF's rho_d, rho_s, phong_n; the background's
// all 0.
std::string encodeGBuffer(int width, int height, const SceneGeometry& geometry,
                          const std::vector<PhongParameters>& brdf);

}  // namespace misalloc
