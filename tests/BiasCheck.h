#pragma once
// Bias tests sized by their power (tests/Statistics.h, BiasFamily) as Catch2 checks.
#include <fmt/format.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <string>

#include "SceneFixtures.h"
#include "Statistics.h"

namespace misalloc::test {

// Adds a test of render(spp, seed) against `expected` to the family, sized to its power:
// a pilot of pilotSpp samples per pixel estimates the error, and the test renders anew,
// under another seed, with the samples that error asks for (at least minSpp, at most 256×
// the pilot). The pilot only sizes the test: its mean is not tested, so the choice of
// the count does not depend on the data tested.
template <typename Render>  // MeanAndError(int spp, uint64_t seed)
void addSized(BiasFamily& family, const std::string& what, double expected, int pilotSpp, int minSpp, uint64_t seed,
              Render render) {
  const MeanAndError pilot = render(pilotSpp, seed);
  const long long wanted = family.samplesFor(pilot.standardError, pilotSpp, expected);
  const int spp = int(std::clamp<long long>(wanted, minSpp, 256LL * pilotSpp));
  const MeanAndError r = render(spp, seed + 0x9e3779b97f4a7c15ull);
  family.add(fmt::format("{}, {} spp", what, spp), r.mean, expected, r.standardError);
}

// A test of an estimate against a closed form.
inline void addEstimate(BiasFamily& family, const std::string& what, const MeanAndError& estimate, double expected) {
  family.add(what, estimate.mean, expected, estimate.standardError);
}

// A test of an estimate against another, independent one where there is no closed form:
// their difference has the errors of both.
inline void addAgreement(BiasFamily& family, const std::string& what, const MeanAndError& estimate,
                         const MeanAndError& reference) {
  family.add(what, estimate.mean, reference.mean, std::hypot(estimate.standardError, reference.standardError));
}

// One failed check per biased or underpowered test, each with its numbers.
inline void checkFamily(const BiasFamily& family) {
  INFO(family.size() << " tests, |z| < " << family.bound() << ", each detects a relative bias of "
                     << family.detectable() << " with probability 0.9");
  CHECK(family.size() > 0);
  for (const std::string& failure : family.failures()) FAIL_CHECK(failure);
}

}  // namespace misalloc::test
