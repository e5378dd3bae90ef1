#pragma once
// The files a shard of a comparison wrote, as its record lists them with a checksum of
// each, and merge's check of them before it copies any: a file deleted, damaged or
// left over from elsewhere would otherwise reach the merged folder unseen (a flipped
// byte inside an image's pixels decodes as well as the original).
#include <map>
#include <string>

namespace misalloc {

struct ShardRecord;

// Every file under `folder` but its record: its path relative to `folder`, and a
// checksum of its bytes (ContentHash.h), in hex.
std::map<std::string, std::string> shardFileChecksums(const std::string& folder);

// Throws InputError, naming the file, unless `folder` holds exactly the files `record`
// lists, each a regular file with the bytes it had, and the record lists every file
// that its cases and runs write (compare/Comparison.h).
void requireShardFiles(const std::string& folder, const ShardRecord& record);

}  // namespace misalloc
