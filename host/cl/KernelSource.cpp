#include "cl/KernelSource.h"

#include <regex>
#include <set>
#include <sstream>

#include "ContentHash.h"
#include "Error.h"

namespace misalloc {
namespace {

std::string directoryOf(const std::string& path) {
  auto slash = path.rfind('/');
  return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

// `#include "x"` resolves against the including file's folder first, `<x>` and
// the fallback against the embedded root. Returns the key, or "" if not embedded.
std::string resolve(const std::string& includer, const std::string& target, bool quoted) {
  const auto& sources = embeddedSources();
  if (quoted && sources.count(directoryOf(includer) + target)) return directoryOf(includer) + target;
  return sources.count(target) ? target : std::string();
}

void expand(const std::string& name, std::set<std::string>& stack, std::ostringstream& out) {
  static const std::regex includeLine(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"].*$)");
  std::istringstream in(embeddedSources().at(name));
  std::string line;
  while (std::getline(in, line)) {
    std::smatch m;
    if (std::regex_match(line, m, includeLine)) {
      std::string key = resolve(name, m[2], m[1] == "\"");
      if (!key.empty()) {
        if (stack.count(key)) throw DeviceError("kernel source include cycle at " + key);
        stack.insert(key);
        expand(key, stack, out);
        stack.erase(key);
        continue;
      }
    }
    out << line << '\n';
  }
}

}  // namespace

std::string kernelSource(const std::string& name) {
  auto it = embeddedSources().find(name);
  if (it == embeddedSources().end()) throw DeviceError("no embedded kernel source named " + name);
  std::set<std::string> stack{name};
  std::ostringstream out;
  expand(name, stack, out);
  return out.str();
}

uint64_t embeddedSourcesHash() {
  static const uint64_t hash = [] {
    ContentHash h;
    for (const auto& [name, text] : embeddedSources()) {  // a std::map: in name order
      h.add(name);
      h.add(text);
    }
    return h.h;
  }();
  return hash;
}

}  // namespace misalloc
