#pragma once
// What every misalloc benchmark shares: an OpenCL kernel and its OpenMP C++ peer run
// side by side in one process, their repetitions interleaved so that the load of other
// processes drifts over both, and closing Markdown tables of medians and ratios, also
// written as JSON by `--summary FILE.json`.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "AtomicFile.h"

namespace misalloc::bench {

// Keeps the median of one counter of every benchmark.
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

// Registers "opencl/NAME" and "openmp/NAME", and "openmp-simd/NAME" where a vectorised
// peer is given: 5 repetitions of at least 0.5 s, medians.
inline void registerPeers(const std::string& name, std::function<void(benchmark::State&)> openCl,
                          std::function<void(benchmark::State&)> openMp,
                          std::function<void(benchmark::State&)> openMpSimd = {}) {
  std::vector<std::pair<const char*, std::function<void(benchmark::State&)>>> impls{{"opencl", openCl},
                                                                                    {"openmp", openMp}};
  if (openMpSimd) impls.emplace_back("openmp-simd", openMpSimd);
  for (auto& [impl, fn] : impls)
    benchmark::RegisterBenchmark(fmt::format("{}/{}", impl, name).c_str(), fn)
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime()
        ->MinTime(0.5)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
}

// Where `--summary` writes the closing tables; empty: nowhere.
inline std::string& summaryPath() {
  static std::string path;
  return path;
}

// Takes the benchmark's own "--flag value" options, and `--summary FILE.json`, out of
// argv, giving each value to its setter, and returns the rest (argv[0] first) for
// Google Benchmark. An unwritable summary path fails here, before any measurement.
inline std::vector<char*> takeFlags(int argc, char** argv,
                                    std::map<std::string, std::function<void(const char*)>> setters) {
  setters.emplace("--summary", [](const char* path) {
    checkWritableOutput(path, "--summary");
    summaryPath() = path;
  });
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
// Its own `--benchmark_out=FILE --benchmark_out_format=json` holds every repetition.
inline void initialize(std::vector<char*> args) {
  static char interleave[] = "--benchmark_enable_random_interleaving=true";
  args.insert(args.begin() + 1, interleave);
  int count = int(args.size());
  benchmark::Initialize(&count, args.data());
}

// One closing table: a row per name with both peers' medians in `unitName`, and their
// ratio OpenCL / OpenMP (above 1: OpenCL has the larger value, which for a time is the
// slower); where a vectorised peer ran too, its median and OpenCL's ratio to it.
// `ratios` false for rows whose ratio means nothing, such as fitted slopes.
struct PeerTable {
  struct Row {
    std::string name;
    double openCl = 0, openMp = 0;
    std::optional<double> openMpSimd;  // "openmp-simd/NAME"
  };
  std::string title;        // what was measured, the sizes and the device
  std::string firstColumn;  // what the row names are
  std::string unitName;
  nlohmann::json config;  // device name and sizes, for the summary
  bool ratios = true;
  std::vector<Row> rows;

  // Appends a row for every name both peers have a median of, the counter's values
  // divided by `unit` (the counter's value of one `unitName`), with the vectorised
  // peer's where it has one.
  PeerTable& addMedians(const MedianCollector& collector, const std::vector<std::string>& names, double unit) {
    const auto& medians = collector.medians;
    for (const auto& name : names) {
      auto cl = medians.find("opencl/" + name), mp = medians.find("openmp/" + name);
      if (cl == medians.end() || mp == medians.end()) continue;
      rows.push_back({name, cl->second / unit, mp->second / unit});
      if (auto simd = medians.find("openmp-simd/" + name); simd != medians.end())
        rows.back().openMpSimd = simd->second / unit;
    }
    return *this;
  }

  bool hasSimdPeer() const {
    return std::any_of(rows.begin(), rows.end(), [](const Row& r) { return r.openMpSimd.has_value(); });
  }

  // Three significant digits, without an exponent for large values.
  static std::string formatValue(double v) {
    return std::abs(v) < 1000 ? fmt::format("{:.3g}", v) : fmt::format("{:.0f}", v);
  }

  std::string markdown() const {
    const bool simd = hasSimdPeer();
    std::string table = fmt::format("{}\n\n| {} | OpenCL {} | OpenMP {} |", title, firstColumn, unitName, unitName);
    std::string rule = "|---|---|---|";
    if (simd) {
      table += fmt::format(" OpenMP simd {} |", unitName);
      rule += "---|";
    }
    if (ratios) {
      table += simd ? " ratio | ratio to simd |" : " ratio |";
      rule += simd ? "---|---|" : "---|";
    }
    table += "\n" + rule + "\n";
    for (const Row& r : rows) {
      table += fmt::format("| {} | {} | {} |", r.name, formatValue(r.openCl), formatValue(r.openMp));
      if (simd) table += fmt::format(" {} |", r.openMpSimd ? formatValue(*r.openMpSimd) : "—");
      if (ratios) table += fmt::format(" {:.2f} |", r.openCl / r.openMp);
      if (ratios && simd) table += r.openMpSimd ? fmt::format(" {:.2f} |", r.openCl / *r.openMpSimd) : " — |";
      table += "\n";
    }
    return table;
  }

  nlohmann::json json() const {
    nlohmann::json out = {{"title", title}, {"config", config}, {"rows", nlohmann::json::array()}};
    for (const Row& r : rows) {
      nlohmann::json row = {{"name", r.name}, {"opencl", r.openCl}, {"openmp", r.openMp}, {"unit", unitName}};
      if (ratios) row["ratio"] = r.openCl / r.openMp;  // OpenCL / OpenMP
      if (r.openMpSimd) {
        row["openmp_simd"] = *r.openMpSimd;
        if (ratios) row["ratio_simd"] = r.openCl / *r.openMpSimd;  // OpenCL / OpenMP simd
      }
      out["rows"].push_back(row);
    }
    return out;
  }
};

// With `--summary`, writes {"tables": tables} there, all at once.
inline void writeSummary(const nlohmann::json& tables) {
  if (!summaryPath().empty()) writeFileAtomically(summaryPath(), nlohmann::json{{"tables", tables}}.dump(2) + "\n");
}

// Prints the tables in Markdown, writes them to the summary
// ({"tables": [{title, config, rows: [{name, opencl, openmp, unit, ratio}]}]}, and
// openmp_simd, ratio_simd in rows with a vectorised peer) and shuts Google Benchmark down.
inline void finish(const std::vector<PeerTable>& tables) {
  nlohmann::json summary = nlohmann::json::array();
  for (const PeerTable& t : tables) {
    std::cout << "\n" << t.markdown();
    summary.push_back(t.json());
  }
  writeSummary(summary);
  benchmark::Shutdown();
}

}  // namespace misalloc::bench
