// The BRDF samplers of kernels/phong.h against the pdfs the estimators divide by, as
// pbrt-v4 and Mitsuba 3 test their BSDFs: directions drawn by the kernels' own
// functions and random numbers are binned on the sphere, and a χ² test compares the
// counts with the pdf integrated over each bin. For both lobes (the split-BRDF
// techniques: sampleDiffuse / diffusePdf, sampleSpecular / specularPdf) and their
// mixture (the BRDF technique: sampleBrdf / brdfPdf), exponents up to 10⁴, views along
// the normal and tilted towards the horizon, normals along the map's z and tilted.
#include <fmt/format.h>

#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <vector>

#include "Constants.h"
#include "KernelCode.h"
#include "Statistics.h"
#include "TestSize.h"

namespace kern = misalloc::kern;
using misalloc::kPi;

namespace {

enum class Lobe { Diffuse, Specular, Mixture };

const char* lobeName(Lobe lobe) {
  return lobe == Lobe::Diffuse ? "diffuse" : lobe == Lobe::Specular ? "specular" : "mixture";
}

// Bins in a frame about the mirror direction r: α = π x² from r (x ∈ [0, 1], so that
// the bins near r resolve a lobe of width ~1/√n down to n = 10⁴) and φ about r.
struct MirrorFrame {
  std::array<double, 3> t, s, r;
};

constexpr int kBinsX = 48, kBinsPhi = 24;

MirrorFrame frameOf(kern::MaVec3 mirror) {
  // The kernel's own basis about r, in double.
  const kern::MaFrame f = kern::frameAbout(mirror);
  return {{f.t.x, f.t.y, f.t.z}, {f.s.x, f.s.y, f.s.z}, {mirror.x, mirror.y, mirror.z}};
}

int binOf(const MirrorFrame& f, kern::MaVec3 w) {
  double x = w.x * f.t[0] + w.y * f.t[1] + w.z * f.t[2];
  double y = w.x * f.s[0] + w.y * f.s[1] + w.z * f.s[2];
  double z = w.x * f.r[0] + w.y * f.r[1] + w.z * f.r[2];
  double alpha = std::atan2(std::hypot(x, y), z), phi = std::atan2(y, x);
  if (phi < 0) phi += 2 * kPi;
  int ix = std::min(kBinsX - 1, int(std::sqrt(alpha / kPi) * kBinsX));
  int ip = std::min(kBinsPhi - 1, int(phi / (2 * kPi) * kBinsPhi));
  return ix * kBinsPhi + ip;
}

struct Setup {
  Lobe lobe;
  kern::PhongParams brdf;
  kern::MaVec3 normal, mirror;
};

float pdfOf(const Setup& c, kern::MaVec3 w) {
  float lobe = kern::phongLobe(c.brdf, w, c.mirror);
  switch (c.lobe) {
    case Lobe::Diffuse:
      return kern::diffusePdf(c.normal, w);
    case Lobe::Specular:
      return kern::specularPdf(c.brdf, lobe);
    default:
      return kern::brdfPdf(c.brdf, c.normal, w, lobe);
  }
}

kern::MaVec3 sampleOf(const Setup& c, const kern::MaRandom4& rnd) {
  float u1 = kern::uniformFloat(rnd.v[1]), u2 = kern::uniformFloat(rnd.v[2]);
  switch (c.lobe) {
    case Lobe::Diffuse:
      return kern::sampleDiffuse(kern::frameAbout(c.normal), u1, u2);
    case Lobe::Specular:
      return kern::sampleSpecular(c.brdf, kern::frameAbout(c.mirror), u1, u2);
    default:
      return kern::sampleBrdf(c.brdf, kern::frameAbout(c.normal), kern::frameAbout(c.mirror), rnd);
  }
}

// The probability of every bin: the pdf integrated over the bin's solid angle,
// dω = sin α dα dφ with dα = 2π x dx, by the midpoint rule on a sub-grid.
std::vector<double> binProbabilities(const Setup& c, const MirrorFrame& f) {
  constexpr int kSubX = 16, kSubPhi = 8;
  std::vector<double> p(kBinsX * kBinsPhi, 0.0);
  const double dx = 1.0 / (kBinsX * kSubX), dphi = 2 * kPi / (kBinsPhi * kSubPhi);
  for (int i = 0; i < kBinsX * kSubX; ++i) {
    double x = (i + 0.5) * dx, alpha = kPi * x * x;
    double weight = std::sin(alpha) * 2 * kPi * x * dx * dphi;
    for (int j = 0; j < kBinsPhi * kSubPhi; ++j) {
      double phi = (j + 0.5) * dphi;
      double lx = std::sin(alpha) * std::cos(phi), ly = std::sin(alpha) * std::sin(phi), lz = std::cos(alpha);
      kern::MaVec3 w =
          kern::makeVec3(float(lx * f.t[0] + ly * f.s[0] + lz * f.r[0]), float(lx * f.t[1] + ly * f.s[1] + lz * f.r[1]),
                         float(lx * f.t[2] + ly * f.s[2] + lz * f.r[2]));
      p[(i / kSubX) * kBinsPhi + j / kSubPhi] += double(pdfOf(c, w)) * weight;
    }
  }
  return p;
}

}  // namespace

TEST_CASE("the BRDF samplers draw directions with the pdfs the estimators use (χ²)", "[brdf][sampler]") {
  const bool small = misalloc::test::smallTestSize();
  // (view°, tilted normal): a pixel's frame is the map's (z up) or turned off it.
  const std::vector<std::pair<double, bool>> views =
      small ? std::vector<std::pair<double, bool>>{{60, true}}
            : std::vector<std::pair<double, bool>>{{0, false}, {45, true}, {80, false}};
  const std::vector<double> exponents = small ? std::vector<double>{20, 1e4} : std::vector<double>{1, 20, 1e3, 1e4};
  const uint64_t samples = small ? 200000 : 1000000;
  const std::vector<Lobe> lobes = {Lobe::Diffuse, Lobe::Specular, Lobe::Mixture};
  const int checks = int(views.size() * exponents.size() * lobes.size());
  const double level = misalloc::test::sidakLevel(0.01, checks);
  uint32_t stream = 0;
  for (const auto& [view, tilted] : views) {
    // ω_o at `view` from the normal; its mirror direction about the normal, in the
    // normal's frame (the kernel's basis about it).
    const double theta = view * kPi / 180;
    const kern::MaVec3 normal =
        tilted ? kern::makeVec3(2.0f / 7, -3.0f / 7, 6.0f / 7) : kern::makeVec3(0.0f, 0.0f, 1.0f);
    const kern::MaVec3 mirror =
        kern::frameToWorld(kern::frameAbout(normal), float(-std::sin(theta)), 0.0f, float(std::cos(theta)));
    for (double n : exponents) {
      for (Lobe lobe : lobes) {
        // The mixture takes most samples from the Phong lobe, as a glossy pixel does.
        Setup c{lobe, {0.3f, 0.7f, float(n)}, normal, mirror};
        MirrorFrame frame = frameOf(mirror);
        std::vector<double> p = binProbabilities(c, frame);
        double total = 0;
        for (double q : p) total += q;
        std::vector<uint64_t> counts(p.size(), 0);
        ++stream;
        for (uint64_t i = 0; i < samples; ++i)
          ++counts[binOf(frame, sampleOf(c, kern::philoxDraw(0xb5df, 0, 0, stream, uint32_t(i))))];
        misalloc::test::ChiSquare test = misalloc::test::chiSquare(counts, p, samples);
        INFO(fmt::format("{} lobe, n {}, view {}°{}: pdf integrates to {}, χ² {} with {} degrees of freedom, p {}",
                         lobeName(lobe), n, view, tilted ? " (tilted normal)" : "", total, test.statistic,
                         test.degreesOfFreedom, test.pValue()));
        // The pdf is a density on the sphere (the specular lobe's part below the
        // horizon included: those samples count and contribute 0).
        CHECK(std::abs(total - 1) < 2e-3);
        CHECK(test.degreesOfFreedom > 10);
        CHECK(test.pValue() > level);
      }
    }
  }
}

TEST_CASE("the BRDF χ² test detects a sampler that does not follow its pdf", "[brdf][sampler]") {
  // The same test against the pdf of a lobe one exponent step away fails: it has the
  // power to see the difference between n and 1.05 n at n = 10⁴.
  kern::MaVec3 normal = kern::makeVec3(0.0f, 0.0f, 1.0f), mirror = kern::makeVec3(-0.5f, 0.0f, float(std::sqrt(0.75)));
  Setup sampled{Lobe::Specular, {0.0f, 1.0f, 1e4f}, normal, mirror},
      assumed{Lobe::Specular, {0.0f, 1.0f, 1.05e4f}, normal, mirror};
  MirrorFrame frame = frameOf(mirror);
  std::vector<double> p = binProbabilities(assumed, frame);
  const uint64_t samples = 200000;
  std::vector<uint64_t> counts(p.size(), 0);
  for (uint64_t i = 0; i < samples; ++i)
    ++counts[binOf(frame, sampleOf(sampled, kern::philoxDraw(0xb5df, 1, 0, 0, uint32_t(i))))];
  CHECK(misalloc::test::chiSquare(counts, p, samples).pValue() < 1e-6);
}
