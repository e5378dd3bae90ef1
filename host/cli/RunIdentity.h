#pragma once
#include <CLI/CLI.hpp>
#include <set>
#include <string>
#include <vector>

#include "scene/Scene.h"

namespace misalloc {

// What a run computes from, as one line: misalloc's version, the command, every option
// but those in `excluded` (outputs, the shard) with its final value, given or default,
// and, in place of the files' names, a hash of what `scenes` read (each envmap's texels,
// each G-buffer's and mesh's bytes). Shards of one run share it, however each spelled
// its options and from wherever it read its files; merge refuses shards whose
// identities differ. Call it once the command has resolved its options (its defaults
// that depend on others written back into the options' variables); throws InputError
// for an input it cannot read.
std::string runIdentity(CLI::App& command, const std::set<std::string>& excluded,
                        const std::vector<SceneOptions>& scenes);

}  // namespace misalloc
