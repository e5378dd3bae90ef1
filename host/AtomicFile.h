#pragma once
#include <string>

namespace misalloc {

// Writes `content` to a new file beside `path` (never over an existing one: its name
// is chosen with O_EXCL) and returns that file's name, so that a caller can rename it
// over `path` once complete. Throws InputError naming `path`; nothing is left behind.
std::string writeTemporaryBeside(const std::string& path, const std::string& content);

// Renames `temporary` over `path`; on failure removes `temporary` and throws
// InputError naming `path`.
void renameIntoPlace(const std::string& temporary, const std::string& path);

// Writes `content` to a temporary file beside `path` and renames it over `path`
// only when complete: a failure or an interruption never leaves a partial file.
void writeFileAtomically(const std::string& path, const std::string& content);

// Throws InputError unless `path`'s folder exists and is writable, so that bad
// output options fail before any work is done.
void checkWritableOutput(const std::string& path, const std::string& option);

}  // namespace misalloc
