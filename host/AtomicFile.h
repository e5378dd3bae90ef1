#pragma once
#include <string>

namespace misalloc {

// Writes `content` to a new file beside `path` (never over an existing one: its name
// is chosen with O_EXCL) and returns that file's name, so that a caller can rename it
// over `path` once complete. Throws InputError naming `path`; nothing is left behind.
// The name is hidden and fits the file system's limit whatever the length of `path`'s
// (temporaryName).
std::string writeTemporaryBeside(const std::string& path, const std::string& content);

// This process's host and PID namespace, as 12 hex digits: a PID names a process only
// there. Temporaries carry it in their names, so that on a file system several machines
// (or containers) share, none is taken for a dead run's by a run elsewhere.
const std::string& hostTag();

// A hidden name beside `path` for a temporary file or folder of this process, unique
// with `attempt`: ".NAME.tmp-HOST-PID-ATTEMPT" (HOST: hostTag), NAME shortened (and a
// hash of it added) where the whole would not fit the file system's limit.
std::string temporaryName(const std::string& path, int attempt);

// Removes what killed runs left in `folder`: temporary files and folders of this user,
// host and PID namespace whose process (the PID in their name) no longer runs; those
// of other hosts are left to them. Once per folder and process.
void removeStaleTemporaries(const std::string& folder);

// Renames `temporary` over `path`; on failure removes `temporary` and throws
// InputError naming `path`.
void renameIntoPlace(const std::string& temporary, const std::string& path);

// Writes `content` to a temporary file beside `path` and renames it over `path`
// only when complete: a failure or an interruption never leaves a partial file.
void writeFileAtomically(const std::string& path, const std::string& content);

// Throws InputError, naming `option`, unless `path` is a regular file or absent and its
// folder exists and is writable, so that bad output options fail before any work is
// done. A device, FIFO or socket is refused: outputs are written beside their target
// and renamed over it, which would replace the special file with a regular one.
void checkWritableOutput(const std::string& path, const std::string& option);

}  // namespace misalloc
