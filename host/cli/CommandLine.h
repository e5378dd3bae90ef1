#pragma once
// The parsing rules every misalloc command line shares, the CLI's and the Python
// module's alike.
#include <CLI/CLI.hpp>

namespace misalloc {

// A repeated option takes its last value, as in most command-line tools. Call before
// the subcommands are added: they copy it.
void setParsingRules(CLI::App& app);

// An option given an empty value ("--out ''") names nothing: a path, a list, a name.
// Refused (InputError) before any work, for every option of `command`; leaving an
// option out is how a default is asked for.
void refuseEmptyValues(const CLI::App& command);

}  // namespace misalloc
