#pragma once
// What every misalloc benchmark shares: an OpenCL kernel and its OpenMP C++ peer run
// side by side in one process, their repetitions interleaved so that the load of other
// processes drifts over both, and a closing Markdown table of medians and ratios.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace misalloc::bench {

// Keeps the median of one rate counter of every benchmark.
class MedianCollector : public benchmark::ConsoleReporter {
 public:
  explicit MedianCollector(std::string counter) : counter_(std::move(counter)) {}
  std::map<std::string, double> medians;

  void ReportRuns(const std::vector<Run>& runs) override {
    for (const Run& r : runs)
      if (r.aggregate_name == "median") medians[r.run_name.function_name] = r.counters.at(counter_).value;
    ConsoleReporter::ReportRuns(runs);
  }

 private:
  std::string counter_;
};

// Registers "opencl/NAME" and "openmp/NAME": 5 repetitions of at least 0.5 s, medians.
inline void registerPeers(const std::string& name, std::function<void(benchmark::State&)> openCl,
                          std::function<void(benchmark::State&)> openMp) {
  for (auto& [impl, fn] : {std::pair{"opencl", openCl}, std::pair{"openmp", openMp}})
    benchmark::RegisterBenchmark(fmt::format("{}/{}", impl, name).c_str(), fn)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MinTime(0.5)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
}

// Takes the benchmark's own "--flag value" options out of argv, giving each value to
// its setter, and returns the rest (argv[0] first) for Google Benchmark.
inline std::vector<char*> takeFlags(int argc, char** argv,
                                    const std::map<std::string, std::function<void(const char*)>>& setters) {
  std::vector<char*> rest{argv[0]};
  for (int i = 1; i < argc; ++i) {
    auto setter = setters.find(argv[i]);
    if (setter != setters.end() && i + 1 < argc)
      setter->second(argv[++i]);
    else
      rest.push_back(argv[i]);
  }
  return rest;
}

// Initialises Google Benchmark with interleaved repetitions (a later flag wins).
inline void initialize(std::vector<char*> args) {
  static char interleave[] = "--benchmark_enable_random_interleaving=true";
  args.insert(args.begin() + 1, interleave);
  int count = int(args.size());
  benchmark::Initialize(&count, args.data());
}

// One row per name: the two medians scaled by `unit` and their ratio.
inline std::string ratioTable(const MedianCollector& collector, const std::vector<std::string>& names,
                              const std::string& firstColumn, const std::string& unitName, double unit) {
  std::string table = fmt::format("| {} | OpenCL {} | OpenMP {} | ratio |\n|---|---|---|---|\n", firstColumn,
                                  unitName, unitName);
  for (const auto& name : names) {
    auto cl = collector.medians.find("opencl/" + name), mp = collector.medians.find("openmp/" + name);
    if (cl == collector.medians.end() || mp == collector.medians.end()) continue;
    table += fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} |\n", name, cl->second / unit, mp->second / unit,
                         cl->second / mp->second);
  }
  return table;
}

}  // namespace misalloc::bench
