#include "NumberList.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "Error.h"

namespace misalloc {

std::vector<double> parseNumberList(const std::string& option, const std::string& value, const std::string& list,
                                    size_t expected, const std::string& forms) {
  std::vector<double> numbers;
  // Split by hand: getline would drop an empty last item ("1,2,").
  for (size_t start = 0; !list.empty() && start <= list.size();) {
    size_t end = std::min(list.find(',', start), list.size());
    const std::string item = list.substr(start, end - start);
    start = end + 1;
    // from_chars, unlike stod, takes no leading space, hex or sign and never throws.
    double v = 0;
    auto [stop, error] = std::from_chars(item.data(), item.data() + item.size(), v);
    if (item.empty() || error != std::errc() || stop != item.data() + item.size() || !std::isfinite(v))
      throw InputError(fmt::format("{} {}: '{}' is not a number ({})", option, value, item, forms));
    numbers.push_back(v);
  }
  if (expected > 0 && numbers.size() != expected)
    throw InputError(fmt::format("{} {}: expected {} numbers ({})", option, value, expected, forms));
  if (numbers.empty()) throw InputError(fmt::format("{} '{}': expected at least one number ({})", option, value, forms));
  return numbers;
}

}  // namespace misalloc
