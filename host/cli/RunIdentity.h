#pragma once
#include <CLI/CLI.hpp>
#include <set>
#include <string>

namespace misalloc {

// The options `command` was given, but those in `excluded` (outputs, the shard), as one
// line in the command's order, with misalloc's version: shards of one run share it, and
// merge refuses shards whose identities differ.
std::string runIdentity(const CLI::App& command, const std::set<std::string>& excluded);

}  // namespace misalloc
