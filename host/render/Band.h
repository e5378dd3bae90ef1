#pragma once
// A sharded render: shard K of N renders a band of the image's rows, whole rows of
// 16-pixel blocks, and `misalloc merge` joins the bands into the image the unsharded
// render writes, bit for bit.
#include <optional>
#include <string>

#include "Shard.h"
#include "render/Reference.h"
#include "render/Render.h"

namespace misalloc {

// Image rows [begin, end).
struct RowRange {
  int begin = 0, end = 0;
  int size() const { return end - begin; }
};

struct Band {
  Shard shard;
  RowRange rows;      // the rows the band writes
  RowRange rendered;  // the rows it renders: its own and those its allocation's pooling reads
};

// The rows beyond a band that its pixels' allocations read: each allocation pools the
// statistics of the pixels within the pool radius, which after the first allocation
// depend on their own neighbours' allocations, so the window widens by the radius
// with every allocation; the optimal weights' coefficients pool the same sums before
// each stage after the first, a fixed split's its pilot's alone; other fixed splits and
// the oracle (by the pixel alone) read none.
// Those rows are rendered with the image's random numbers (Scene::firstPixel), so
// their pilots and stages are those the neighbouring band draws.
int poolingHaloRows(Method method, const AdaptiveOptions& options);

// Shard K's band of an image of `height` rows: the block rows split as evenly as
// possible, the earlier bands taking one more. Throws InputError when there are fewer
// block rows than shards (a band would be empty).
Band bandOf(Shard shard, int height, int haloRows);

// The rows `rows` of `image` as a scene of their own, keyed on the image's pixels. It
// keeps the envmap's tables: pass the image by std::move where it is not needed after.
Scene bandScene(Scene image, RowRange rows);

// The rows `rows` of a render of the rows `rendered` (image rows both).
Rendering cropRendering(const Rendering& rendering, int width, int techniques, RowRange rendered, RowRange rows);

// The rows `rows` of a whole image's reference.
Reference cropReference(const Reference& reference, RowRange rows);

}  // namespace misalloc
