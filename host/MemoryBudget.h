#pragma once
// Refusing, before allocating, what this machine cannot hold: a clear message naming
// the option beats a std::bad_alloc halfway through a run.
#include <cstdint>
#include <string>

namespace misalloc {

// What one pixel of a render keeps on the host beyond its statistics: the BRDF
// parameters, the image (float and its double sums), the variance, and per technique
// the counts, first indices, moments and α (about 200 B for M = 3), rounded up.
constexpr uint64_t kRenderBytesPerPixel = 256;

// Throws InputError unless `bytes` fit in this machine's physical memory. `what` names
// the option and its value and says how the figure arises, e.g. "--size 40000x40000
// (1.6e9 pixels × 256 B)". A double, so that products of options cannot overflow.
void requireHostMemory(const std::string& what, double bytes);

}  // namespace misalloc
