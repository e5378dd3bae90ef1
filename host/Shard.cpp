#include "Shard.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <vector>

#include "Error.h"

namespace misalloc {
namespace {

// A decimal int of digits only, or nullopt.
std::optional<int> digitsValue(const std::string& text) {
  if (text.empty() || text.size() > 9 || text.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  return std::stoi(text);
}

// The identity's entries, in order.
std::vector<std::string> identityEntries(const std::string& identity) {
  std::vector<std::string> entries;
  for (size_t begin = 0; begin <= identity.size();) {
    const size_t end = std::min(identity.find("; ", begin), identity.size());
    entries.push_back(identity.substr(begin, end - begin));
    begin = end + 2;
  }
  return entries;
}

}  // namespace

std::string runDifference(const std::string& a, const std::string& b) {
  const std::vector<std::string> x = identityEntries(a), y = identityEntries(b);
  for (size_t i = 0; i < std::max(x.size(), y.size()); ++i) {
    const std::string left = i < x.size() ? x[i] : "nothing", right = i < y.size() ? y[i] : "nothing";
    if (left != right) return fmt::format("{} against {}", left, right);
  }
  return "no difference";
}

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
