#pragma once
#include <string>
#include <vector>

namespace misalloc {

// "a,b,c" as finite numbers; exactly `expected` of them, or any number but none when
// `expected` is 0. Throws InputError naming
// the option, the whole value and the offending item, followed by `forms`.
std::vector<double> parseNumberList(const std::string& option, const std::string& value, const std::string& list,
                                    size_t expected, const std::string& forms);

}  // namespace misalloc
