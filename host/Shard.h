#pragma once
#include <string>

namespace misalloc {

// Shard K of N of a run split over processes or nodes (render --shard, compare --shard),
// 0 ≤ K < N.
struct Shard {
  int index = 0, count = 1;
};

// "K/N"; throws InputError naming `option` unless 0 ≤ K < N.
Shard parseShard(const std::string& text, const std::string& option);

// Where two runs' identities (cli/RunIdentity.h: entries joined by "; ") first differ,
// for merge's refusal: "--seed 1 against --seed 2".
std::string runDifference(const std::string& a, const std::string& b);

}  // namespace misalloc
