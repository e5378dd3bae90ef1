#pragma once
// The built-in scenes (--scene): what each pixel sees, as a G-buffer would hold it.
#include <string>
#include <vector>

#include "scene/BrdfGrid.h"
#include "scene/SceneGeometry.h"

namespace misalloc {

// plane: [HS14] Sec. 5.2's rectangle, the BRDF grid over the image. sphere: one
// sphere, the grid over its visible half. spheres: a grid of spheres, one BRDF each, as
// material previews show them.
struct SceneShape {
  enum Kind { Plane, Sphere, Spheres } kind = Plane;
  int columns = 1, rows = 1;  // spheres: how many across and down
};

// "plane", "sphere", "spheres" (4x4) or "spheres:CxR". Throws InputError naming --scene.
SceneShape parseSceneShape(const std::string& spec);

// The polar angle of the view (degrees) where --view is not given: the plane from
// above ([HS14]'s view), spheres from 15° above the horizon.
double defaultViewTheta(const SceneShape& shape);

// What each pixel sees of the shape, by an orthographic camera looking along −ω_o
// (ω_o at polar angle θ and azimuth φ, degrees, in the map's frame), image up towards
// the map's z: its frame and coverage, and where it reads the BRDF grid.
struct ShapeImage {
  SceneGeometry geometry;
  std::vector<SurfaceUv> uv;
};
// Throws InputError naming --view where the angle cannot show the shape.
ShapeImage shapeImage(const SceneShape& shape, int width, int height, double viewThetaDegrees, double viewPhiDegrees);

}  // namespace misalloc
