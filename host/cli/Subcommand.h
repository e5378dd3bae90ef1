#pragma once
#include <CLI/CLI.hpp>
#include <functional>

namespace misalloc {

// One subcommand of misalloc: `add…Command(app)` adds it and its options to `app`,
// keeping the values they parse into, and `run`, called once `app` has parsed a command
// line that chose it, does its work and returns the exit code. Errors are thrown and
// mapped to exit codes by main (host/main.cpp).
struct Subcommand {
  CLI::App* command;
  std::function<int()> run;
};

Subcommand addDevicesCommand(CLI::App& app);    // DevicesCommand.cpp
Subcommand addRenderCommand(CLI::App& app);     // RenderCommand.cpp
Subcommand addReferenceCommand(CLI::App& app);  // ReferenceCommand.cpp
Subcommand addCompareCommand(CLI::App& app);    // CompareCommand.cpp
Subcommand addPaperCommand(CLI::App& app);      // PaperCommand.cpp
Subcommand addMergeCommand(CLI::App& app);      // MergeCommand.cpp
Subcommand addGBufferCommand(CLI::App& app);    // GBufferCommand.cpp

}  // namespace misalloc
