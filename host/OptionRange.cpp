#include "OptionRange.h"

#include <fmt/format.h>

#include <charconv>
#include <climits>
#include <cmath>

#include "Error.h"

namespace misalloc {
namespace {

// Whether std::from_chars reads all of `text` as a T in range.
template <typename T>
bool parseAll(const std::string& text, T& value) {
  const char* end = text.data() + text.size();
  auto [stop, error] = std::from_chars(text.data(), end, value);
  return error == std::errc() && stop == end;
}

std::string interval(double lo, double hi, bool openLo, bool openHi) {
  return fmt::format("{}{:g}, {:g}{}", openLo ? "(" : "[", lo, hi, openHi ? ")" : "]");
}

// Why `text` is not what the option takes, or "" when it is.
std::string integerProblem(const std::string& text, long long lo, long long hi) {
  long long value = 0;
  if (!parseAll(text, value) || value < lo || value > hi)
    return fmt::format("'{}' is not a whole number in [{}, {}]", text, lo, hi);
  return "";
}

std::string unsignedProblem(const std::string& text) {
  uint64_t value = 0;
  if (!parseAll(text, value)) return fmt::format("'{}' is not a whole number in [0, {}]", text, UINT64_MAX);
  return "";
}

std::string realProblem(const std::string& text, double lo, double hi, bool openLo, bool openHi) {
  double value = 0;
  bool inside = parseAll(text, value) && std::isfinite(value) && (openLo ? value > lo : value >= lo) &&
                (openHi ? value < hi : value <= hi);
  if (!inside) return fmt::format("'{}' is not a finite number in {}", text, interval(lo, hi, openLo, openHi));
  return "";
}

}  // namespace

CLI::Validator integerIn(long long lo, long long hi) {
  return CLI::Validator([lo, hi](std::string& text) { return integerProblem(text, lo, hi); },
                        fmt::format("INT in [{}, {}]", lo, hi));
}

CLI::Validator anyUnsigned64() {
  return CLI::Validator([](std::string& text) { return unsignedProblem(text); }, "UINT64");
}

CLI::Validator realIn(double lo, double hi, bool openLo, bool openHi) {
  return CLI::Validator(
      [=](std::string& text) { return realProblem(text, lo, hi, openLo, openHi); },
      "FLOAT in " + interval(lo, hi, openLo, openHi));
}

std::pair<int, int> parseImageSize(const std::string& text) {
  size_t x = text.find('x');
  int width = 0, height = 0;
  bool ok = x != std::string::npos && parseAll(text.substr(0, x), width) && parseAll(text.substr(x + 1), height) &&
            width >= 1 && height >= 1;
  if (!ok) throw InputError(fmt::format("--size {}: expected WxH with whole numbers W, H ≥ 1", text));
  if (int64_t(width) * height > INT_MAX)
    throw InputError(fmt::format("--size {}: {} pixels; the kernels index at most {}", text, int64_t(width) * height,
                                 INT_MAX));
  return {width, height};
}

}  // namespace misalloc
