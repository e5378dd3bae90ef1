// Throughput of the exact allocation's grid search (000 Algorithm 1) in evaluations
// per second (pixels × U × samples): kernels/gridsearch.cl on an OpenCL device (PoCL by
// default) side by side, in one run, with its OpenMP C++ peer (gridSearchReference,
// compiled by g++ -O3 -march=native), for both selection rules.
//
//   build/bench/misalloc_bench_gridsearch [--device cpu] [--size 256] [--grid-u 160] [--samples 200]
//                                         [--techniques 2] [google benchmark flags]
//
// Ends with a Markdown table of medians and the OpenCL/OpenMP ratio.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <cmath>
#include <cstring>
#include <iostream>
#include <map>
#include <random>

#include "KernelCode.h"
#include "alloc/GridSearch.h"
#include "cl/Device.h"

using namespace misalloc;

namespace {

struct Config {
    std::string device = "cpu";
    int size = 256, gridSize = kDefaultGridSize, samples = 200, techniques = 2;
} config;

const std::pair<const char*, GridRule> kRules[] = {
    {"min cost x variance", GridRule::MinCostVariance},
    {"max entropy", GridRule::MaxEntropy},
};

const Device& device() {
    static const Device d = openDevice(config.device);
    return d;
}

StoredSampleLayout benchLayout() {
    return StoredSampleLayout{config.size * config.size, config.techniques, config.samples, config.samples};
}

// Every pixel integrates its own f(x) = x^e + b on [0, 1] with the techniques
// p_k = (k + 1) x^k, in stages of kStageSamples as kernels/sample.cl stores them: each
// stage's samples technique by technique, counts from the pixel's random mixture. The
// searches are distinct and well posed, and f > 0, so no sample is skipped by the peer.
constexpr int kStageSamples = 50;

const std::vector<float>& benchSamples() {
    static const std::vector<float> samples = [] {
        StoredSampleLayout layout = benchLayout();
        const int m = layout.techniqueCount;
        std::vector<float> s(layout.floatCount(), 1.0f);
        std::mt19937_64 rng(1);
        std::uniform_real_distribution<double> uniform(0.0, 1.0);
        for (int pixel = 0; pixel < (layout.pixelCount + 15) / 16 * 16; ++pixel) {
            double exponent = 0.5 + 2 * uniform(rng), offset = 0.05 + 0.5 * uniform(rng), mix = 0.2 + 0.6 * uniform(rng);
            int firstCount = int(mix * kStageSamples);
            for (int i = 0; i < layout.taken; ++i) {
                auto at = [&](int q) -> float& { return s[kern::storedSampleIndex(pixel, i, q, layout.capacity, m)]; };
                int j = i % kStageSamples;
                int k = j < firstCount ? 0 : 1 + (j - firstCount) * (m - 1) / (kStageSamples - firstCount);
                double x = std::pow(uniform(rng), 1.0 / (k + 1));
                at(0) = float(k);
                at(1) = pixel < layout.pixelCount ? float(std::pow(x, exponent) + offset) : 0.0f;
                for (int l = 0; l < m; ++l) at(2 + l) = float((l + 1) * std::pow(x, l));
            }
        }
        return s;
    }();
    return samples;
}

std::vector<double> benchCosts() { return std::vector<double>(config.techniques, 1.0); }

void setRate(benchmark::State& state) {
    StoredSampleLayout layout = benchLayout();
    int gridSize = makeWeightGrid(layout.techniqueCount, config.gridSize, benchCosts()).size();
    state.counters["evaluations/s"] = benchmark::Counter(double(layout.pixelCount) * gridSize * layout.taken,
                                                         benchmark::Counter::kIsIterationInvariantRate);
}

void benchOpenCl(benchmark::State& state, GridRule rule) {
    const std::vector<float>& samples = benchSamples();
    cl::Buffer buffer(device().context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, samples.size() * sizeof(float),
                      const_cast<float*>(samples.data()));
    GridSearch search(device(), config.techniques);
    search.run(buffer, benchLayout(), benchCosts(), config.gridSize, rule);  // warm-up: first-launch JIT
    for (auto _ : state)
        benchmark::DoNotOptimize(search.run(buffer, benchLayout(), benchCosts(), config.gridSize, rule).selected.data());
    setRate(state);
}

void benchOpenMp(benchmark::State& state, GridRule rule) {
    const std::vector<float>& samples = benchSamples();
    for (auto _ : state)
        benchmark::DoNotOptimize(
            gridSearchReference(samples, benchLayout(), benchCosts(), config.gridSize, rule).selected.data());
    setRate(state);
}

// Keeps the median evaluations/s of every benchmark for the closing table.
class MedianCollector : public benchmark::ConsoleReporter {
  public:
    std::map<std::string, double> medians;
    void ReportRuns(const std::vector<Run>& runs) override {
        for (const Run& r : runs)
            if (r.aggregate_name == "median") medians[r.run_name.function_name] = r.counters.at("evaluations/s").value;
        ConsoleReporter::ReportRuns(runs);
    }
};

}  // namespace

int main(int argc, char** argv) {
    std::vector<char*> rest;
    for (int i = 0; i < argc; ++i) {
        auto value = [&](const char* flag) { return std::strcmp(argv[i], flag) == 0 && i + 1 < argc; };
        if (value("--device")) config.device = argv[++i];
        else if (value("--size")) config.size = std::stoi(argv[++i]);
        else if (value("--grid-u")) config.gridSize = std::stoi(argv[++i]);
        else if (value("--samples")) config.samples = std::stoi(argv[++i]);
        else if (value("--techniques")) config.techniques = std::stoi(argv[++i]);
        else rest.push_back(argv[i]);
    }
    int restCount = int(rest.size());
    benchmark::Initialize(&restCount, rest.data());
    for (const auto& [name, rule] : kRules) {
        for (const char* impl : {"opencl", "openmp"}) {
            auto fn = std::string(impl) == "opencl" ? benchOpenCl : benchOpenMp;
            GridRule r = rule;
            benchmark::RegisterBenchmark(fmt::format("{}/{}", impl, name).c_str(), [fn, r](benchmark::State& s) { fn(s, r); })
                ->Unit(benchmark::kMillisecond)
                ->UseRealTime()
                ->MinTime(0.5)
                ->Repetitions(5)
                ->ReportAggregatesOnly(true);
        }
    }
    MedianCollector reporter;
    benchmark::RunSpecifiedBenchmarks(&reporter);
    std::cout << fmt::format("\nGrid search, {}x{} pixels, M = {}, U = {}, {} samples, OpenCL device: {}\n\n", config.size,
                             config.size, config.techniques,
                             makeWeightGrid(config.techniques, config.gridSize, benchCosts()).size(), config.samples,
                             device().name())
              << "| rule | OpenCL G evaluations/s | OpenMP G evaluations/s | ratio |\n|---|---|---|---|\n";
    for (const auto& [name, rule] : kRules) {
        auto cl = reporter.medians.find(fmt::format("opencl/{}", name));
        auto mp = reporter.medians.find(fmt::format("openmp/{}", name));
        if (cl == reporter.medians.end() || mp == reporter.medians.end()) continue;
        std::cout << fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} |\n", name, cl->second * 1e-9, mp->second * 1e-9,
                                 cl->second / mp->second);
    }
    benchmark::Shutdown();
}
