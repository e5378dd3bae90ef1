#include "NumberList.h"

#include <fmt/format.h>

#include <cmath>
#include <sstream>

#include "Error.h"

namespace misalloc {

std::vector<double> parseNumberList(const std::string& option, const std::string& value, const std::string& list,
                                    size_t expected, const std::string& forms) {
  std::vector<double> numbers;
  std::stringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    size_t used = 0;
    double v = 0;
    try {
      v = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(v))
      throw InputError(fmt::format("{} {}: '{}' is not a number ({})", option, value, item, forms));
    numbers.push_back(v);
  }
  if (expected > 0 && numbers.size() != expected)
    throw InputError(fmt::format("{} {}: expected {} numbers ({})", option, value, expected, forms));
  if (numbers.empty()) throw InputError(fmt::format("{} '{}': expected at least one number ({})", option, value, forms));
  return numbers;
}

}  // namespace misalloc
