#pragma once
// A stable 64-bit content hash for cache keys and checksums (the references' and the
// optimal pdf's tables'). It takes 8 bytes per multiply: a key hashes every texel of a
// map, and a cache hit must cost a small part of the work it saves.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <type_traits>
#include <vector>

#include "Error.h"

namespace misalloc {

struct ContentHash {
  uint64_t h = 0x9e3779b97f4a7c15ull;

  void add(const void* data, std::size_t n) {
    auto* p = static_cast<const unsigned char*>(data);
    std::size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      uint64_t w;
      std::memcpy(&w, p + i, 8);
      mix(w);
    }
    uint64_t tail = n;  // the length too, so that "ab" + "c" and "a" + "bc" differ
    for (; i < n; ++i) tail = (tail << 8) | p[i];
    mix(tail);
  }
  void add(const std::string& s) { add(s.data(), s.size()); }
  template <typename T>
  void addValue(T v) {
    static_assert(std::is_trivially_copyable_v<T>);
    add(&v, sizeof v);
  }
  // A vector's elements as bytes, its length with them.
  template <typename T>
  void addVector(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    add(v.data(), v.size() * sizeof(T));
  }

 private:
  void mix(uint64_t w) {
    h = (h ^ w) * 0xff51afd7ed558ccdull;
    h ^= h >> 32;
  }
};

// The hash of a file's bytes, for identities and checksums of files as written; throws
// InputError naming `what` (an option, a path) if it cannot be read.
inline uint64_t fileContentHash(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  if (!in.good() && !in.eof()) throw InputError(what + ": cannot be read");
  ContentHash h;
  h.add(bytes);
  return h.h;
}

}  // namespace misalloc
