#pragma once
#include <cstdint>
#include <map>
#include <string>

namespace misalloc {

// Kernel sources and the Random123 headers they include, embedded at build time
// (cmake/EmbedKernels.cmake), keyed by include path.
const std::map<std::string, std::string>& embeddedSources();

// The text of an embedded kernel file with its embedded #includes expanded in
// place, so the OpenCL compiler needs no include path. Includes of files that are not
// embedded are left alone: they only occur in branches the OpenCL compiler skips.
std::string kernelSource(const std::string& name);

// A hash of every embedded file, names and texts: what the kernels are built from, and
// what the host's C++ reference (KernelCode.h) compiles too.
uint64_t embeddedSourcesHash();

}  // namespace misalloc
