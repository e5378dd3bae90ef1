#include "MemoryBudget.h"

#include <fmt/format.h>
#include <unistd.h>

#include "Error.h"

namespace misalloc {
namespace {

uint64_t physicalMemoryBytes() { return uint64_t(::sysconf(_SC_PHYS_PAGES)) * uint64_t(::sysconf(_SC_PAGESIZE)); }

std::string gibibytes(double bytes) { return fmt::format("{:.3g} GiB", bytes / double(1ull << 30)); }

}  // namespace

void requireHostMemory(const std::string& what, double bytes) {
  const double available = double(physicalMemoryBytes());
  if (bytes > available)
    throw InputError(fmt::format("{} needs {} of memory; this machine has {}", what, gibibytes(bytes),
                                 gibibytes(available)));
}

}  // namespace misalloc
