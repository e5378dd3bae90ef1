#pragma once
// A band of a sharded render as a file: its rows as an EXR whose header says which run
// and which rows they are, where they ran, and the band's report; and the merge of a
// run's bands into its image.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "render/Band.h"
#include "scene/ExrIO.h"

namespace misalloc {

struct BandRecord {
  std::string run;  // the run's options but those naming outputs (bands of one run share it)
  Band band;
  int width = 0, height = 0;  // the whole image's
  std::string node;           // the host the band ran on
  nlohmann::json report;      // the band's render report
};

// The band's rows (its image, band.rows.size() rows) as an EXR with the record in its header.
std::string encodeBand(const RgbImage& rows, const BandRecord& record);

struct MergedRender {
  RgbImage image;
  nlohmann::json report;  // the run, and per band its rows, node, times and report
};

// Joins the bands at `paths` into the whole image. Throws InputError, naming the file,
// for a file that is not a band, bands of different runs or images, a band given
// twice, and bands that overlap or leave rows out.
MergedRender mergeBands(const std::vector<std::string>& paths);

// This host's name, for the records of where shards ran.
std::string nodeName();

}  // namespace misalloc
