#include "render/Band.h"

#include <fmt/format.h>

#include <algorithm>

#include "Constants.h"
#include "Error.h"

namespace misalloc {
namespace {

// Elements [rows.begin, rows.end) of a row-major array of `perRow` values a row, whose
// row 0 is image row `firstRow`.
template <typename T>
std::vector<T> rowsOf(const std::vector<T>& values, size_t perRow, int firstRow, RowRange rows) {
  const auto begin = values.begin() + ptrdiff_t(size_t(rows.begin - firstRow) * perRow);
  return std::vector<T>(begin, begin + ptrdiff_t(size_t(rows.size()) * perRow));
}

RgbImage cropImage(const RgbImage& image, int firstRow, RowRange rows) {
  RgbImage out{image.width, rows.size(), rowsOf(image.rgb, size_t(image.width) * 3, firstRow, rows), {}};
  if (!image.alpha.empty()) out.alpha = rowsOf(image.alpha, size_t(image.width), firstRow, rows);
  return out;
}

}  // namespace

int poolingHaloRows(Method method, const AdaptiveOptions& options) {
  const MethodTraits& traits = methodTraits(method);
  if (traits.split == Split::Staged) return options.poolRadius * options.stages;
  // A fixed split with optimal weights pools its pilot's sums once (render/Render.cpp).
  if (traits.split == Split::Fixed && options.weights == MisWeights::Optimal) return options.poolRadius;
  return 0;
}

Band bandOf(Shard shard, int height, int haloRows) {
  const int blockRows = (height + kPixelBlock - 1) / kPixelBlock;
  if (blockRows < shard.count)
    throw InputError(
        fmt::format("--shard {}/{}: the image's {} rows make {} row(s) of {}-pixel blocks, fewer than "
                    "the {} bands",
                    shard.index, shard.count, height, blockRows, kPixelBlock, shard.count));
  const int per = blockRows / shard.count, extra = blockRows % shard.count;
  const int first = shard.index * per + std::min(shard.index, extra);
  const int last = first + per + (shard.index < extra ? 1 : 0);
  Band band{shard, {first * kPixelBlock, std::min(height, last * kPixelBlock)}, {}};
  band.rendered = {std::max(0, band.rows.begin - haloRows), std::min(height, band.rows.end + haloRows)};
  return band;
}

Scene bandScene(Scene image, RowRange rows) {
  const size_t width = size_t(image.grid.width);
  image.firstPixel += int(size_t(rows.begin) * width);
  image.grid.height = rows.size();
  image.grid.pixels = rowsOf(image.grid.pixels, width, 0, rows);
  image.geometry.pixels = rowsOf(image.geometry.pixels, width, 0, rows);
  image.geometry.covered = rowsOf(image.geometry.covered, width, 0, rows);
  image.surfaces = rowsOf(image.surfaces, width, 0, rows);
  image.options.height = rows.size();
  if (image.tables.hasBank()) image.tables.brdfBinOfPixel = rowsOf(image.tables.brdfBinOfPixel, width, 0, rows);
  // Its tables now map the band's pixels only: never cached under the image's key.
  image.bankCacheKey.clear();
  return image;
}

Rendering cropRendering(const Rendering& rendering, int width, int techniques, RowRange rendered, RowRange rows) {
  Rendering band = rendering;
  band.image = cropImage(rendering.image, rendered.begin, rows);
  band.variance = rowsOf(rendering.variance, size_t(width), rendered.begin, rows);
  band.alpha = rowsOf(rendering.alpha, size_t(width) * techniques, rendered.begin, rows);
  return band;
}

Reference cropReference(const Reference& reference, RowRange rows) {
  Reference band = reference;
  band.image = cropImage(reference.image, 0, rows);
  if (!reference.standardError.empty())
    band.standardError = rowsOf(reference.standardError, size_t(reference.image.width) * 3, 0, rows);
  return band;
}

}  // namespace misalloc
