#pragma once
#include <string>

namespace misalloc {

// Writes `content` to a temporary file beside `path` and renames it over `path`
// only when complete: a failure or an interruption never leaves a partial file.
void writeFileAtomically(const std::string& path, const std::string& content);

// Throws InputError unless `path`'s folder exists and is writable, so that bad
// output options fail before any work is done.
void checkWritableOutput(const std::string& path, const std::string& option);

}  // namespace misalloc
