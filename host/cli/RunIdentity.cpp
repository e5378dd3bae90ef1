#include "cli/RunIdentity.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>

#include "ContentHash.h"
#include "Error.h"
#include "scene/Envmap.h"

namespace misalloc {
namespace {

// The options that name a file: the identity holds the file's content instead, so that
// one file reached by two paths (a relative path from two folders) is one input, and
// two files of one name are two.
const std::set<std::string> kInputOptions{"--envmap", "--gbuffer", "--mesh"};

// An option's final value in one spelling. CLI11 converts an option's variable to text
// with its default function: called after the command resolved its options, it gives
// the value the run used, whether given (in any spelling: `--seed 01`) or left at its
// default (the parse is over: the help's default text is no longer read). Flags have
// no variable CLI11 can read: given or not; an option without a variable, its text.
std::string finalValue(CLI::Option& option) {
  if (option.get_expected_max() == 0) return option.count() > 0 && option.as<bool>() ? "true" : "false";
  option.default_str("");
  option.capture_default_str();
  if (!option.get_default_str().empty() || option.count() == 0) return option.get_default_str();
  return fmt::format("{}", fmt::join(option.results(), " "));
}

// A value's comma-separated items that are whole finite numbers in one spelling, the
// shortest that reads back as the same double: a text option that holds numbers
// (`--cost 1.0,2` and `--cost 1,2e0`) has one value however it was typed.
std::string canonicalNumbers(const std::string& value) {
  std::vector<std::string> items;
  size_t begin = 0;
  while (true) {
    const size_t end = value.find(',', begin);
    std::string item = value.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
    char* parsed = nullptr;
    const double number = item.empty() ? 0 : std::strtod(item.c_str(), &parsed);
    if (!item.empty() && parsed == item.c_str() + item.size() && std::isfinite(number))
      item = fmt::format("{}", number);
    items.push_back(std::move(item));
    if (end == std::string::npos) break;
    begin = end + 1;
  }
  return fmt::format("{}", fmt::join(items, ","));
}

uint64_t envmapTexelHash(const SceneOptions& scene) {
  const Envmap map = makeEnvmap(resolveEnvmapSpec(scene.envmap), scene.proceduralWidth);
  ContentHash h;
  h.addValue(map.image.width);
  h.addValue(map.image.height);
  h.addValue(map.coskExponent);
  h.addVector(map.image.rgb);
  return h.h;
}

// A hash of each file the scene read, or of its procedural map's texels.
void addInputHashes(const SceneOptions& scene, std::vector<std::string>& entries) {
  entries.push_back(fmt::format("envmap texels {:016x}", envmapTexelHash(scene)));
  if (!scene.gbuffer.path.empty())
    entries.push_back(
        fmt::format("gbuffer bytes {:016x}", fileContentHash(scene.gbuffer.path, "--gbuffer " + scene.gbuffer.path)));
  if (!scene.mesh.path.empty())
    entries.push_back(fmt::format("mesh bytes {:016x}", fileContentHash(scene.mesh.path, "--mesh " + scene.mesh.path)));
}

}  // namespace

std::string runIdentity(CLI::App& command, const std::set<std::string>& excluded,
                        const std::vector<SceneOptions>& scenes) {
  std::vector<std::string> entries{fmt::format("misalloc {} {}", MISALLOC_VERSION, command.get_name())};
  for (CLI::Option* option : command.get_options()) {
    const std::string& name = option->get_name();
    if (excluded.count(name) || kInputOptions.count(name)) continue;
    entries.push_back(fmt::format("{} {}", name, canonicalNumbers(finalValue(*option))));
  }
  for (const SceneOptions& scene : scenes) addInputHashes(scene, entries);
  return fmt::format("{}", fmt::join(entries, "; "));
}

}  // namespace misalloc
