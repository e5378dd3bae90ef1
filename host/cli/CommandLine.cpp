#include "cli/CommandLine.h"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <vector>

#include "Error.h"

namespace misalloc {

void setParsingRules(CLI::App& app) { app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast); }

void refuseEmptyValues(const CLI::App& command) {
  for (const CLI::Option* option : command.get_options()) {
    const std::vector<std::string>& values = option->results();
    if (std::find(values.begin(), values.end(), std::string()) != values.end())
      throw InputError(fmt::format("{}: an empty value{}", option->get_name(),
                                   option->get_required() ? "" : "; leave the option out for its default"));
  }
}

}  // namespace misalloc
