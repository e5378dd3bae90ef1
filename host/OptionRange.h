#pragma once
// Numeric command-line values, parsed in full range and checked against what they mean.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

namespace misalloc {

// `text` as a whole number in [lo, hi], or an explanation of why not ("" when it is
// one). std::from_chars reads it: no sign wrapping, no exponent, nothing after it, and
// a value beyond long long is out of range, not wrapped.
std::string integerProblem(const std::string& text, long long lo, long long hi);

// The same for an unsigned 64-bit number, 0 to 2^64 − 1 (seeds).
std::string unsignedProblem(const std::string& text);

// `text` as a finite number in [lo, hi], the ends excluded when `openLo`/`openHi`.
std::string realProblem(const std::string& text, double lo, double hi, bool openLo = false, bool openHi = false);

// The same checks as CLI11 validators, which run on the text before CLI11 converts it,
// so that a bad value is refused with its option's name (CLI::ValidationError).
CLI::Validator integerIn(long long lo, long long hi);
CLI::Validator anyUnsigned64();
CLI::Validator realIn(double lo, double hi, bool openLo = false, bool openHi = false);

// "WxH" with W, H ≥ 1 and W·H within the kernels' int pixel indices; throws InputError
// naming --size.
std::pair<int, int> parseImageSize(const std::string& text);

}  // namespace misalloc
