#pragma once
// A triangle mesh seen by a pinhole camera (--mesh): what a renderer's G-buffer would
// hold for it, each pixel's smooth-shaded frame and coverage, found by casting the
// pixel's ray through its centre at the triangles (no anti-aliasing).
#include <string>

#include "scene/GBuffer.h"

namespace misalloc {

struct MeshOptions {
  std::string path;                // OBJ, PLY, or any format Assimp reads; empty: no mesh
  std::string target = "0,0,0";    // X,Y,Z: where the camera looks, in the mesh's world
  double verticalFovDegrees = 40;  // in (0, 180)
};

// The mesh in `gbuffer.convention`'s world (its map orientation too), seen from
// `gbuffer.cameraOrigin` towards `mesh.target`, image up towards the world's up (z;
// Mitsuba's y), on width × height pixels. Throws InputError naming the file or option:
// a file Assimp cannot read or without triangles, a missing or bad camera, a mesh that
// covers no pixel.
GBufferImage rasteriseMesh(const MeshOptions& mesh, const GBufferOptions& gbuffer, int width, int height);

}  // namespace misalloc
