// Exact's whole-image rule (alloc/WholeImageRule.h): the image's predicted gain from the
// pixels' held-out variances and the costs, and the rule that keeps equal counts on it.
#include <catch2/catch.hpp>
#include <cmath>
#include <optional>
#include <vector>

#include "alloc/WholeImageRule.h"

using namespace misalloc;

namespace {

// Pixels with held-out variances (equal, α) and weights α, every pixel covered.
StageAllocation allocationOf(const std::vector<std::pair<float, float>>& variances,
                             const std::vector<std::vector<double>>& alphas) {
  StageAllocation a = equalStageAllocation(int(variances.size()), 2);
  for (size_t p = 0; p < variances.size(); ++p) {
    a.heldOutVariance.push_back(variances[p].first);
    a.heldOutVariance.push_back(variances[p].second);
    a.allocations[p].alpha = alphas[p];
  }
  return a;
}

}  // namespace

TEST_CASE("the image's predicted gain sums the pixels' variances and costs", "[image]") {
  const std::vector<double> half{0.5, 0.5}, same{1.0, 1.0};
  const std::vector<unsigned char> all{1, 1};
  // Every pixel's variance halved at equal cost: twice the efficiency.
  CHECK(*predictedImageGain(allocationOf({{4, 2}, {1, 0.5f}}, {half, half}), same, all) == Approx(2.0));
  // Sums, not a mean of ratios: the noisy pixel decides. (100 + 1) / (100 + 0.1).
  CHECK(*predictedImageGain(allocationOf({{100, 100}, {1, 0.1f}}, {half, half}), same, all) == Approx(101.0 / 100.1));
  // The costs of the image's samples: every pixel moved to the technique of cost 3 pays
  // 3 per sample against equal counts' 2.
  CHECK(*predictedImageGain(allocationOf({{4, 2}, {1, 0.5f}}, {{0, 1}, {0, 1}}), {1.0, 3.0}, all) ==
        Approx(2.0 * 2.0 / 3.0));
  // The background takes no samples: neither its variances nor its costs count.
  CHECK(*predictedImageGain(allocationOf({{4, 2}, {1e6f, 1}}, {half, {0, 1}}), {1.0, 3.0}, {1, 0}) == Approx(2.0));
  // A pixel without held-out variances adds none, but it still takes its samples.
  CHECK(*predictedImageGain(allocationOf({{4, 2}, {NAN, NAN}}, {half, {0, 1}}), {1.0, 3.0}, all) ==
        Approx(2.0 * 4.0 / 5.0));
  // Nothing to predict from: no pooled selection; and a pilot that saw no variance.
  CHECK_FALSE(predictedImageGain(allocationOf({{NAN, NAN}, {NAN, NAN}}, {half, half}), same, all));
  StageAllocation unpredicted = equalStageAllocation(2, 2);
  CHECK_FALSE(predictedImageGain(unpredicted, same, all));
  CHECK(*predictedImageGain(allocationOf({{0, 0}, {0, 0}}, {half, half}), same, all) == 1.0);
}

TEST_CASE("the whole-image rule keeps equal counts below its threshold only", "[image]") {
  CHECK(keepsEqualCounts(0.9, 1.1));
  CHECK_FALSE(keepsEqualCounts(1.1, 1.1));
  CHECK_FALSE(keepsEqualCounts(0.5, 0.0));
  CHECK_FALSE(keepsEqualCounts(std::nullopt, 1.1));
  StageAllocation equal = equalStageAllocation(3, 2);
  REQUIRE(equal.allocations.size() == 3);
  for (size_t p = 0; p < 3; ++p) {
    CHECK(equal.allocations[p].alpha == std::vector<double>{0.5, 0.5});
    CHECK(equal.skipped[p] == 1);
    CHECK(equal.varianceRatio[p] == 1.0f);
  }
}
