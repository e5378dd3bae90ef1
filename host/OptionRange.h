#pragma once
// Numeric command-line values, parsed in full range and checked against what they mean.
#include <CLI/CLI.hpp>
#include <string>
#include <utility>

namespace misalloc {

// CLI11 validators. They run on the text before CLI11 converts it, and read it with
// std::from_chars in full: no sign wrapping, no exponent in a whole number, nothing
// after the number, NaN and ±Inf refused, and a value beyond the type is out of range,
// not wrapped. CLI11 then refuses a bad value naming its option (CLI::ValidationError).
CLI::Validator integerIn(long long lo, long long hi);  // a whole number in [lo, hi]
CLI::Validator anyUnsigned64();                        // 0 to 2^64 − 1 (seeds)
// A finite number in [lo, hi], the ends excluded when `openLo`/`openHi`.
CLI::Validator realIn(double lo, double hi, bool openLo = false, bool openHi = false);

// "WxH" with W, H ≥ 1 and W·H within the kernels' int pixel indices; throws InputError
// naming --size.
std::pair<int, int> parseImageSize(const std::string& text);

}  // namespace misalloc
