// misalloc: per-pixel MIS sample allocation for envmap × BRDF direct lighting. The
// subcommands live in host/cli/; here are their order, the parsing rules they share, and
// the exit codes: 2 for bad input, 3 for an OpenCL error, 1 for anything else.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <limits>
#include <new>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <vector>

#include "Error.h"
#include "cl/Device.h"
#include "cli/CommandLine.h"
#include "cli/Subcommand.h"

using namespace misalloc;

namespace {

// CLI11 takes a word it does not know for a stray argument; say what it is instead.
void refuseUnknownSubcommand(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return;
  std::vector<std::string> names;
  for (const CLI::App* sub : app.get_subcommands({})) names.push_back(sub->get_name());
  if (std::find(names.begin(), names.end(), argv[1]) == names.end())
    throw InputError(fmt::format("unknown subcommand '{}'; the subcommands are {}", argv[1], fmt::join(names, ", ")));
}

// A render allocates each stage's sums afresh: 30–100 MB at 1024×1024. glibc serves
// blocks that large with fresh pages from the kernel and returns them when freed, so
// every stage paid a page fault per 4 KiB on first touch: half the host's time at
// 1024×1024 on the EPYC and most of it on a GPU (docs/results.md, "The host's page
// faults"). Kept in the heap, a freed block serves the next stage; the process's peak
// memory is what it was.
void keepFreedBlocksInHeap() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_MAX, 0);
  mallopt(M_TRIM_THRESHOLD, std::numeric_limits<int>::max());
#endif
}

}  // namespace

int main(int argc, char** argv) {
  keepFreedBlocksInHeap();
  CLI::App app{"misalloc: per-pixel allocation of MIS samples for envmap x BRDF direct lighting"};
  app.require_subcommand(1);
  setParsingRules(app);
  const std::vector<Subcommand> subcommands{addDevicesCommand(app), addRenderCommand(app), addReferenceCommand(app),
                                            addCompareCommand(app), addPaperCommand(app),  addMergeCommand(app),
                                            addGBufferCommand(app)};
  try {
    refuseUnknownSubcommand(app, argc, argv);
    app.parse(argc, argv);
    for (const Subcommand& s : subcommands)
      if (app.got_subcommand(s.command)) {
        refuseEmptyValues(*s.command);
        return s.run();
      }
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "misalloc: error: " << e.what() << "\nRun with --help for more information.\n";
    return 2;  // CLI11's own codes (104–114) would each mean "bad input" too
  } catch (const InputError& e) {
    std::cerr << "misalloc: error: " << e.what() << "\n";
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    std::cerr << "misalloc: error: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    std::cerr << "misalloc: error: out of memory: --size, --spp and --grid-u of the adaptive methods, and the "
                 "envmap's texels decide how much a run needs\n";
    return 2;
  } catch (const DeviceError& e) {
    std::cerr << "misalloc: OpenCL error: " << e.what() << "\n";
    return 3;
  } catch (const cl::Error& e) {
    std::cerr << "misalloc: OpenCL error: " << e.what() << " (code " << e.err() << ")\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "misalloc: internal error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
