#pragma once
// A pairwise covering set: of a list of configurations, a subset in which every pair of
// settings that occurs together in some configuration of the list occurs together in
// one configuration of the subset. A bug that needs one setting, or two settings
// together, to show is then exercised by the subset as by the whole list; one that needs
// three at once may be missed, which the exhaustive run (scripts/exhaustive-tests) is
// for. A configuration is a list of settings "name=value" (each name once in it); names
// that a configuration lacks are settings it does not have (e.g. the product's tables
// without the product).
//
// The subset is chosen greedily, as AETG chooses its rows (Cohen et al. 1997, "The AETG
// system"): repeatedly the configuration that covers the most pairs not yet covered, the
// first of them in the list on a tie, until every pair is covered. Only the list's own
// configurations are chosen, so a combination that the host would never build (refused
// by requireValidRun, or skipped by a caller) is never added. The result depends on the
// list alone: the same list gives the same subset on every machine and in every run.
#include <algorithm>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "TestSize.h"

namespace misalloc::test {

using Configuration = std::vector<std::string>;  // settings "name=value"

inline std::vector<std::pair<std::string, std::string>> settingPairs(const Configuration& configuration) {
  Configuration sorted = configuration;
  std::sort(sorted.begin(), sorted.end());
  sorted.erase(std::unique(sorted.begin(), sorted.end()), sorted.end());
  std::vector<std::pair<std::string, std::string>> pairs;
  for (size_t a = 0; a < sorted.size(); ++a)
    for (size_t b = a + 1; b < sorted.size(); ++b) pairs.emplace_back(sorted[a], sorted[b]);
  // A configuration of one setting still has to be covered: as the pair with itself.
  if (sorted.size() == 1) pairs.emplace_back(sorted[0], sorted[0]);
  return pairs;
}

// Indices into `configurations`, in increasing order, of a subset that covers every
// pair of settings the list holds.
inline std::vector<size_t> pairwiseCovering(const std::vector<Configuration>& configurations) {
  std::vector<std::vector<std::pair<std::string, std::string>>> pairsOf;
  std::set<std::pair<std::string, std::string>> uncovered;
  for (const Configuration& c : configurations) {
    pairsOf.push_back(settingPairs(c));
    uncovered.insert(pairsOf.back().begin(), pairsOf.back().end());
  }
  std::vector<size_t> chosen;
  while (!uncovered.empty()) {
    size_t best = 0, bestCount = 0;
    for (size_t i = 0; i < pairsOf.size(); ++i) {
      const size_t count = size_t(std::count_if(pairsOf[i].begin(), pairsOf[i].end(),
                                                [&](const auto& pair) { return uncovered.count(pair) > 0; }));
      if (count > bestCount) best = i, bestCount = count;
    }
    for (const auto& pair : pairsOf[best]) uncovered.erase(pair);
    chosen.push_back(best);
  }
  std::sort(chosen.begin(), chosen.end());
  return chosen;
}

// The configurations a test runs: a pairwise covering set, or with
// MISALLOC_TEST_SIZE=exhaustive (scripts/exhaustive-tests) every one.
inline std::vector<size_t> configurationsToRun(const std::vector<Configuration>& configurations) {
  if (!exhaustiveTestSize()) return pairwiseCovering(configurations);
  std::vector<size_t> all(configurations.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  return all;
}

}  // namespace misalloc::test
