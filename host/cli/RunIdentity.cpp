#include "cli/RunIdentity.h"

#include <fmt/format.h>

namespace misalloc {

std::string runIdentity(const CLI::App& command, const std::set<std::string>& excluded) {
  std::string identity = fmt::format("misalloc {} {}", MISALLOC_VERSION, command.get_name());
  for (const CLI::Option* option : command.get_options()) {
    if (option->count() == 0 || excluded.count(option->get_name())) continue;
    identity += " " + option->get_name();
    for (const std::string& value : option->results()) identity += " " + value;
  }
  return identity;
}

}  // namespace misalloc
