#pragma once
// Which pixels show one surface, for the pooled allocations (alloc/Pooling.h): a pixel's
// allocation is estimated from its neighbours' statistics, which says something about
// it only where they see the same surface. A sphere's rim borders the background and,
// in the image, other objects, whose lighting and BRDF have nothing to do with its own.
#include <cstdint>
#include <vector>

#include "scene/BrdfGrid.h"
#include "scene/SceneGeometry.h"

namespace misalloc {

// The connected parts of the covered pixels (4-neighbours) over which normals turn by
// less than kSurfaceEdgeDegrees and BRDFs change by less than kSurfaceEdgeAlbedo in ρd
// and ρs and a factor kSurfaceEdgeExponentRatio in n + 1, from one pixel to the next:
// one label per part, in raster order of first pixel; −1 on the background. The bounds
// keep a smooth gradient one surface (seed000 over 16 pixels steps ρd by up to 0.12 and
// n + 1 by 1.8×, a tessellated sphere's rim its normals by under 10°), and cut where a
// normal or a material jumps.
std::vector<int32_t> labelSurfaces(const SceneGeometry& geometry, const BrdfGrid& grid);

inline constexpr double kSurfaceEdgeDegrees = 30;
inline constexpr double kSurfaceEdgeAlbedo = 0.2;
inline constexpr double kSurfaceEdgeExponentRatio = 2;

}  // namespace misalloc
