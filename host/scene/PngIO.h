#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace misalloc {

// The bytes of an 8-bit RGB PNG (3 bytes per pixel, row 0 at the top).
std::string encodePng(int width, int height, const std::vector<uint8_t>& rgb);

// Writes encodePng's bytes through a temporary file renamed over `path` once
// complete (host/AtomicFile.h).
void writePng(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb);

}  // namespace misalloc
