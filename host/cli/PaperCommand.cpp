// misalloc paper [ID]: the papers' 1D examples, listed, or one printed against the
// papers' numbers.
#include <fmt/format.h>

#include <algorithm>
#include <iostream>
#include <memory>

#include "Error.h"
#include "cli/Subcommand.h"
#include "paper/PaperReport.h"

namespace misalloc {

Subcommand addPaperCommand(CLI::App& app) {
  auto* command = app.add_subcommand("paper", "the papers' 1D examples: list them, or print one against the papers");
  auto id = std::make_shared<std::string>();
  command->add_option("id", *id, "example id (see `misalloc paper`)");
  return {command, [id] {
            if (id->empty()) {
              listPaperExamples(std::cout);
              return 0;
            }
            const std::vector<std::string> ids = paperIds();
            if (std::find(ids.begin(), ids.end(), *id) == ids.end())
              throw InputError(fmt::format("paper {}: unknown example; valid ids: {}", *id, fmt::join(ids, ", ")));
            printPaperExample(*id, std::cout);
            return 0;
          }};
}

}  // namespace misalloc
