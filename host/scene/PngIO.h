#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace misalloc {

// Writes 8-bit RGB (3 bytes per pixel, row 0 at the top) as PNG, through a temporary
// file renamed over `path` once complete (host/AtomicFile.h).
void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

}  // namespace misalloc
