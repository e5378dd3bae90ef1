#include "scene/PngIO.h"

#include <fmt/format.h>
#include <png.h>

#include <stdexcept>

#include "AtomicFile.h"

namespace misalloc {
namespace {

void appendToString(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), length);
}

}  // namespace

std::string encodePng(int width, int height, const std::vector<uint8_t>& rgb) {
  if (rgb.size() != size_t(width) * height * 3) throw std::invalid_argument("writePng: wrong pixel count");
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw std::runtime_error("libpng could not start");
  }
  std::string encoded;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error(fmt::format("libpng failed to encode a {}×{} image", width, height));
  }
  png_set_write_fn(png, &encoded, appendToString, nullptr);
  png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) png_write_row(png, const_cast<png_bytep>(rgb.data() + size_t(y) * width * 3));
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return encoded;
}

void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb) {
  writeFileAtomically(path, encodePng(width, height, rgb));
}

}  // namespace misalloc
