#include "Shard.h"

#include <fmt/format.h>

#include <optional>

#include "Error.h"

namespace misalloc {
namespace {

// A decimal int of digits only, or nullopt.
std::optional<int> digitsValue(const std::string& text) {
  if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoi(text);
}

}  // namespace

Shard parseShard(const std::string& text, const std::string& option) {
  const size_t slash = text.find('/');
  const std::optional<int> k = digitsValue(text.substr(0, slash));
  const std::optional<int> n = slash == std::string::npos ? std::nullopt : digitsValue(text.substr(slash + 1));
  const Shard shard{k.value_or(-1), n.value_or(-1)};
  if (shard.index < 0 || shard.index >= shard.count)
    throw InputError(fmt::format("{} '{}': expected K/N, shard K of N with 0 <= K < N", option, text));
  return shard;
}

}  // namespace misalloc
