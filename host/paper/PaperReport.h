#pragma once
// `misalloc paper`: every number the papers print for their 1D examples next to ours.

#include <iosfwd>
#include <map>
#include <string>
#include <vector>

#include "paper/PaperExamples.h"

namespace misalloc {

// Every id that `misalloc paper` lists and prints: the 1D examples (paperExampleIds),
// then [Kar19]'s flatland test.
std::vector<std::string> paperIds();

// One line per example: its id and what it integrates.
void listPaperExamples(std::ostream& out);

// The example's published values next to ours with a verdict on each, then a seeded
// Monte Carlo run of every allocation rule on it. Throws std::invalid_argument listing
// the valid ids for an unknown id.
void printPaperExample(const std::string& id, std::ostream& out);

// Our value of every quantity in publishedValues(id), formatted as printed.
std::map<std::string, std::string> reproducedValues(const std::string& id);

}  // namespace misalloc
