#pragma once
// What the papers print for their 1D examples, with the verdict of an independent
// high-precision reproduction (shared/papers/verified_values.json), as data.

#include <optional>
#include <string>
#include <vector>

namespace misalloc {

struct PublishedValue {
  const char* quantity;   // the row label; the report computes our value under the same label
  const char* published;  // as printed, or nullptr where the paper gives no value
  const char* source;     // where it is printed
  const char* verdict;
};

// The rows of one example in print order. Throws std::invalid_argument for an unknown id.
const std::vector<PublishedValue>& publishedValues(const std::string& exampleId);

// verified_values.json, [SS23] "linear heuristic MC study (200 runs x 100 samples/technique)":
// quantiles of the exact variance at the heuristic's α, from an independent implementation.
// Not in the paper; an expectation for ours.
struct VarianceQuantiles {
  double median, p10, p90;
};
struct LinearHeuristicReference {
  VarianceQuantiles dropMostNegative, minSampleVariance;
};
std::optional<LinearHeuristicReference> linearHeuristicReference(const std::string& exampleId);

}  // namespace misalloc
