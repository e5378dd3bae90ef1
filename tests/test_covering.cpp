// The pairwise covering set (tests/Covering.h) that kernel = reference, the statistical
// sweeps and the PTX test run instead of their full products.
#include <catch2/catch.hpp>
#include <set>
#include <string>

#include "Covering.h"

using namespace misalloc::test;

namespace {

std::vector<Configuration> product(int factors, int levels) {
  std::vector<Configuration> all{{}};
  for (int f = 0; f < factors; ++f) {
    std::vector<Configuration> next;
    for (const Configuration& c : all)
      for (int l = 0; l < levels; ++l) {
        Configuration longer = c;
        longer.push_back("f" + std::to_string(f) + "=" + std::to_string(l));
        next.push_back(longer);
      }
    all = next;
  }
  return all;
}

std::set<std::pair<std::string, std::string>> pairsOf(const std::vector<Configuration>& list,
                                                      const std::vector<size_t>& picked) {
  std::set<std::pair<std::string, std::string>> pairs;
  for (size_t i : picked)
    for (const auto& p : settingPairs(list[i])) pairs.insert(p);
  return pairs;
}

std::vector<size_t> everyIndex(size_t n) {
  std::vector<size_t> all(n);
  for (size_t i = 0; i < n; ++i) all[i] = i;
  return all;
}

}  // namespace

TEST_CASE("a pairwise covering set covers every pair of settings with far fewer configurations", "[covering]") {
  const std::vector<Configuration> all = product(5, 3);  // 243 configurations
  const std::vector<size_t> picked = pairwiseCovering(all);
  CHECK(pairsOf(all, picked) == pairsOf(all, everyIndex(all.size())));
  // 9 is the least any set can have (3 × 3 levels of two factors); greedy sets stay near it.
  CHECK(picked.size() >= 9);
  CHECK(picked.size() <= 15);
  CHECK(pairwiseCovering(all) == picked);  // deterministic
}

TEST_CASE("a covering set keeps the one configuration that holds a rare pair, and only given ones", "[covering]") {
  std::vector<Configuration> list = product(3, 2);
  // Only the last configuration has the product on; with it comes a setting of its own.
  list.push_back({"f0=1", "f1=1", "f2=1", "product=1", "tables=4"});
  const std::vector<size_t> picked = pairwiseCovering(list);
  CHECK(std::count(picked.begin(), picked.end(), list.size() - 1) == 1);
  for (size_t i : picked) CHECK(i < list.size());
  CHECK(pairsOf(list, picked) == pairsOf(list, everyIndex(list.size())));
  // One setting alone is covered too.
  CHECK(pairwiseCovering({{"a=1"}, {"a=2"}}) == std::vector<size_t>{0, 1});
}
