#include "alloc/GridSearch.h"

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <stdexcept>
#include <cstdlib>

#include "KernelCode.h"
namespace misalloc::kern {
#include "gridsearch.h"
}  // namespace misalloc::kern

namespace misalloc {

static_assert(MA_FALLBACK_NON_FINITE == kFallbackNonFinite && MA_FALLBACK_TOO_FEW_SAMPLES == kFallbackTooFewSamples &&
                  MA_FALLBACK_NO_SIGNAL == kFallbackNoSignal &&
                  MA_FALLBACK_SILENT_TECHNIQUE == kFallbackSilentTechnique &&
                  MA_FALLBACK_SINGULAR_SYSTEM == kFallbackSingularSystem,
              "kernels/gridsearch.h must use the bits of AllocationFallback");
static_assert(MA_GRID_MAX_TECHNIQUES == kMaxTechniques);

namespace {

// Weight combinations summed per pass over the samples: 4 · 2M float16 accumulators
// for M = 2 and 2 · 2M for M ≥ 3 keep them, the sample and the α in 32 registers.
int gridChunk(int techniqueCount) { return techniqueCount == 2 ? 4 : 2; }

void checkTechniqueCount(int techniqueCount) {
    if (techniqueCount < 2 || techniqueCount > kMaxTechniques)
        throw std::invalid_argument(fmt::format("grid search: {} techniques; it needs 2 to {}", techniqueCount,
                                                kMaxTechniques));
}

void checkLayout(const StoredSampleLayout& layout, int techniqueCount, std::size_t availableFloats) {
    if (layout.techniqueCount != techniqueCount)
        throw std::invalid_argument(fmt::format("grid search: samples of {} techniques, search built for {}",
                                                layout.techniqueCount, techniqueCount));
    if (layout.pixelCount < 0 || layout.taken < 0 || layout.taken > layout.capacity)
        throw std::invalid_argument(fmt::format("grid search: {} pixels, {} of {} samples taken", layout.pixelCount,
                                                layout.taken, layout.capacity));
    if (availableFloats < layout.floatCount())
        throw std::invalid_argument(fmt::format("grid search: the samples hold {} floats, the layout needs {}",
                                                availableFloats, layout.floatCount()));
}

// Appends every a ≥ 0 with Σ_k a_k = remaining over the techniques k ≥ first, in
// lexicographic order, as the weights (a_k + 1/M) / (r + 1).
void appendLattice(std::vector<int>& a, int first, int remaining, int resolution, std::vector<float>& alpha) {
    int m = static_cast<int>(a.size());
    if (first == m - 1) {
        a[first] = remaining;
        for (int k = 0; k < m; ++k) alpha.push_back(float((a[k] + 1.0 / m) / (resolution + 1)));
        return;
    }
    for (a[first] = 0; a[first] <= remaining; ++a[first])
        appendLattice(a, first + 1, remaining - a[first], resolution, alpha);
}

// C(r + M − 1, M − 1): the lattice points of resolution r.
long latticeSize(int techniqueCount, int resolution) {
    long n = 1;
    for (int k = 1; k < techniqueCount; ++k) n = n * (resolution + k) / k;
    return n;
}

int closestResolution(int techniqueCount, int approximateSize) {
    int r = 0;
    while (latticeSize(techniqueCount, r + 1) <= approximateSize) ++r;
    long below = latticeSize(techniqueCount, r), above = latticeSize(techniqueCount, r + 1);
    return above - approximateSize <= approximateSize - below ? r + 1 : r;
}

std::vector<float> toFloats(const std::vector<double>& values) { return std::vector<float>(values.begin(), values.end()); }

// What the kernel's summarise() finds for one pixel, by the same float operations.
struct PixelSummary {
    float count[kMaxTechniques] = {}, maxF[kMaxTechniques] = {};
    float scale = 1.0f;
    int invalid = 0;
};

PixelSummary summarisePixel(const float* samples, const StoredSampleLayout& layout, int pixel) {
    const int m = layout.techniqueCount;
    auto at = [&](int i, int q) { return samples[kern::storedSampleIndex(pixel, i, q, layout.capacity, m)]; };
    PixelSummary s;
    float maxRatio = 0.0f;
    for (int i = 0; i < layout.taken; ++i) {
        float technique = at(i, 0), f = at(i, 1), pSum = at(i, 2);
        for (int k = 1; k < m; ++k) pSum += at(i, 2 + k);
        s.invalid |= !(f >= 0.0f && f <= FLT_MAX) || (f > 0.0f && pSum == 0.0f);
        for (int k = 0; k < m; ++k) s.invalid |= !(at(i, 2 + k) >= 0.0f && at(i, 2 + k) <= FLT_MAX);
        maxRatio = std::max(maxRatio, f / (pSum == 0.0f ? 1.0f : pSum));
        int j = static_cast<int>(technique);
        if (!(technique >= 0.0f && technique < m && j == technique)) {
            s.invalid = 1;
            continue;
        }
        s.count[j] += 1.0f;
        s.maxF[j] = std::max(s.maxF[j], f);
    }
    s.scale = maxRatio == 0.0f ? 1.0f : 1.0f / maxRatio;
    return s;
}

// The inputs of one search, shared by every pixel.
struct SearchSetup {
    const float* samples;
    StoredSampleLayout layout;
    WeightGrid grid;
    std::vector<float> alphaByTechnique;  // [k·U + l]: the innermost loop runs over l
    std::vector<float> cost;              // c_k
    int rule;
};

// Σ g and Σ g² over each technique's samples for every l, g = scale · f / p_α
// (000 Alg. 1 line 8). A sample with f = 0 adds nothing. M is a template argument so
// that the loop over l is the only loop left to vectorise.
template <int M>
void sumPixel(const SearchSetup& setup, int pixel, float scale, std::vector<float>& sumG, std::vector<float>& sumG2) {
    const int u = setup.grid.size();
    std::fill(sumG.begin(), sumG.end(), 0.0f);
    std::fill(sumG2.begin(), sumG2.end(), 0.0f);
    auto at = [&](int i, int q) { return setup.samples[kern::storedSampleIndex(pixel, i, q, setup.layout.capacity, M)]; };
    const float* alpha = setup.alphaByTechnique.data();
    for (int i = 0; i < setup.layout.taken; ++i) {
        float fs = at(i, 1) * scale;
        if (fs == 0.0f) continue;
        float pdf[M];
        for (int k = 0; k < M; ++k) pdf[k] = at(i, 2 + k);
        float* g1 = sumG.data() + static_cast<int>(at(i, 0)) * u;
        float* g2 = sumG2.data() + static_cast<int>(at(i, 0)) * u;
#pragma omp simd
        for (int l = 0; l < u; ++l) {
            float p = alpha[l] * pdf[0];
            for (int k = 1; k < M; ++k) p = std::fma(alpha[k * u + l], pdf[k], p);
            float g = fs / p;
            g1[l] += g;
            g2[l] = std::fma(g, g, g2[l]);
        }
    }
}

void sumPixel(const SearchSetup& setup, int pixel, float scale, std::vector<float>& sumG, std::vector<float>& sumG2) {
    switch (setup.layout.techniqueCount) {
        case 2: return sumPixel<2>(setup, pixel, scale, sumG, sumG2);
        case 3: return sumPixel<3>(setup, pixel, scale, sumG, sumG2);
        default: return sumPixel<4>(setup, pixel, scale, sumG, sumG2);
    }
}

// 000 Alg. 1 lines 5–13 for one pixel.
void searchPixel(const SearchSetup& setup, int pixel, std::vector<float>& sumG, std::vector<float>& sumG2,
                 Allocation& allocation, int& selected) {
    const int m = setup.layout.techniqueCount, u = setup.grid.size();
    PixelSummary summary = summarisePixel(setup.samples, setup.layout, pixel);
    unsigned fallbacks = kern::pixelFallbacks(m, summary.count, summary.maxF, summary.invalid);
    int best = -1;
    if (fallbacks == 0) {
        sumPixel(setup, pixel, summary.scale, sumG, sumG2);
        float bestScore = -INFINITY;
        for (int l = 0; l < u; ++l) {
            float g1[kMaxTechniques], g2[kMaxTechniques];
            for (int j = 0; j < m; ++j) {
                g1[j] = sumG[j * u + l];
                g2[j] = sumG2[j * u + l];
            }
            float score = kern::gridScore(setup.rule, m, &setup.grid.alpha[l * m], setup.grid.cost[l],
                                          setup.cost.data(), g1, g2, summary.count);
            if (score > bestScore) {
                bestScore = score;
                best = l;
            }
        }
        if (best < 0)
            fallbacks = setup.rule == MA_RULE_MAX_ENTROPY ? kFallbackSingularSystem : kFallbackNonFinite;
    }
    selected = fallbacks == 0 ? best : -1;
    if (fallbacks != 0) {
        allocation = equalFallback(m, fallbacks);
        return;
    }
    allocation = Allocation{std::vector<double>(&setup.grid.alpha[best * m], &setup.grid.alpha[best * m] + m)};
}

int kernelRule(GridRule rule) { return rule == GridRule::MaxEntropy ? MA_RULE_MAX_ENTROPY : MA_RULE_MIN_COST_VARIANCE; }

}  // namespace

WeightGrid makeWeightGrid(int techniqueCount, int approximateSize, const std::vector<double>& costs) {
    checkTechniqueCount(techniqueCount);
    validateCosts(costs, techniqueCount);
    if (approximateSize < 1) throw std::invalid_argument("grid search: the grid needs at least one combination");
    int resolution = closestResolution(techniqueCount, approximateSize);
    WeightGrid grid;
    grid.techniqueCount = techniqueCount;
    std::vector<int> a(techniqueCount);
    appendLattice(a, 0, resolution, resolution, grid.alpha);
    for (std::size_t l = 0; l < grid.alpha.size() / techniqueCount; ++l) {
        double meanCost = 0;
        for (int k = 0; k < techniqueCount; ++k) meanCost += costs[k] * grid.alpha[l * techniqueCount + k];
        grid.cost.push_back(float(meanCost));
    }
    return grid;
}

std::size_t StoredSampleLayout::floatCount() const {
    return (std::size_t(pixelCount) + 15) / 16 * 16 * std::size_t(capacity) * std::size_t(techniqueCount + 2);
}

int GridSearchResult::fallbackCount() const {
    return static_cast<int>(std::count_if(allocations.begin(), allocations.end(),
                                          [](const Allocation& a) { return a.usedFallback(); }));
}

GridSearch::GridSearch(const Device& device, int techniqueCount) : device_(device), techniqueCount_(techniqueCount) {
    checkTechniqueCount(techniqueCount);
    cl::Program program = buildProgram(device, "gridsearch.cl",
                                       fmt::format("-cl-std=CL1.2 -DMA_TECHNIQUES={} -DMA_GRID_CHUNK={} {}",
                                                   techniqueCount, std::getenv("GS_CHUNK") ? std::atoi(std::getenv("GS_CHUNK")) : gridChunk(techniqueCount), std::getenv("GS_OPTS") ? std::getenv("GS_OPTS") : ""));
    kernel_ = cl::Kernel(program, "gridSearch");
}

GridSearchResult GridSearch::run(const cl::Buffer& samples, const StoredSampleLayout& layout,
                                 const std::vector<double>& costs, int gridSize, GridRule rule) {
    checkLayout(layout, techniqueCount_, samples.getInfo<CL_MEM_SIZE>() / sizeof(float));
    WeightGrid grid = makeWeightGrid(techniqueCount_, gridSize, costs);
    const int m = techniqueCount_, pixels = layout.pixelCount;
    GridSearchResult result;
    if (pixels == 0) return result;
    auto upload = [&](std::vector<float> data) {
        return cl::Buffer(device_.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, data.size() * sizeof(float),
                          data.data());
    };
    cl::Buffer gridAlpha = upload(grid.alpha), gridCost = upload(grid.cost), cost = upload(toFloats(costs));
    cl::Buffer alphaOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * m * sizeof(float));
    cl::Buffer selectedOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(cl_int));
    cl::Buffer fallbacksOut(device_.context, CL_MEM_WRITE_ONLY, std::size_t(pixels) * sizeof(cl_uint));
    int a = 0;
    kernel_.setArg(a++, samples);
    kernel_.setArg(a++, cl_int(layout.capacity));
    kernel_.setArg(a++, cl_int(layout.taken));
    kernel_.setArg(a++, cl_int(pixels));
    kernel_.setArg(a++, gridAlpha);
    kernel_.setArg(a++, gridCost);
    kernel_.setArg(a++, cl_int(grid.size()));
    kernel_.setArg(a++, cost);
    kernel_.setArg(a++, cl_int(kernelRule(rule)));
    kernel_.setArg(a++, alphaOut);
    kernel_.setArg(a++, selectedOut);
    kernel_.setArg(a++, fallbacksOut);
    cl::Event done;
    device_.queue.enqueueNDRangeKernel(kernel_, cl::NullRange, cl::NDRange((pixels + 15) / 16), cl::NullRange, nullptr,
                                       &done);
    done.wait();
    result.seconds = double(done.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                            done.getProfilingInfo<CL_PROFILING_COMMAND_START>()) *
                     1e-9;

    std::vector<float> alpha(std::size_t(pixels) * m);
    std::vector<cl_uint> fallbacks(pixels);
    result.selected.resize(pixels);
    device_.queue.enqueueReadBuffer(alphaOut, CL_FALSE, 0, alpha.size() * sizeof(float), alpha.data());
    device_.queue.enqueueReadBuffer(selectedOut, CL_FALSE, 0, pixels * sizeof(cl_int), result.selected.data());
    device_.queue.enqueueReadBuffer(fallbacksOut, CL_TRUE, 0, pixels * sizeof(cl_uint), fallbacks.data());
    result.allocations.reserve(pixels);
    for (int p = 0; p < pixels; ++p) {
        const float* a = &alpha[std::size_t(p) * m];
        result.allocations.push_back(fallbacks[p] != 0 ? equalFallback(m, fallbacks[p])
                                                       : Allocation{std::vector<double>(a, a + m)});
    }
    return result;
}

GridSearchResult gridSearchReference(const std::vector<float>& samples, const StoredSampleLayout& layout,
                                     const std::vector<double>& costs, int gridSize, GridRule rule) {
    checkTechniqueCount(layout.techniqueCount);
    checkLayout(layout, layout.techniqueCount, samples.size());
    SearchSetup setup{samples.data(), layout, makeWeightGrid(layout.techniqueCount, gridSize, costs), {},
                      toFloats(costs), kernelRule(rule)};
    const int m = layout.techniqueCount, u = setup.grid.size();
    setup.alphaByTechnique.resize(std::size_t(m) * u);
    for (int l = 0; l < u; ++l)
        for (int k = 0; k < m; ++k) setup.alphaByTechnique[k * u + l] = setup.grid.alpha[l * m + k];

    GridSearchResult result;
    result.allocations.resize(layout.pixelCount);
    result.selected.resize(layout.pixelCount);
    auto start = std::chrono::steady_clock::now();
#pragma omp parallel
    {
        std::vector<float> sumG(std::size_t(m) * u), sumG2(std::size_t(m) * u);  // [j·U + l]
#pragma omp for schedule(dynamic, 16)
        for (int pixel = 0; pixel < layout.pixelCount; ++pixel)
            searchPixel(setup, pixel, sumG, sumG2, result.allocations[pixel], result.selected[pixel]);
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace misalloc
