#pragma once
#include <string>
#include <vector>

#include "sampling/Sampler.h"

namespace misalloc {

// The cost c_k of one sample of each technique alone, in seconds, measured on the
// device in use from the sampling kernel's own timing (profiling events; wall time for
// the host sampler): the median of 5 stages of `spp` samples per pixel, all of them
// technique k's, after a warm-up launch. `calibration` must keep no statistics.
std::vector<double> measureCosts(StageSampler& calibration, int spp = 16);

// "--cost c1,c2[,c3]": one positive number per technique, else InputError.
std::vector<double> parseCosts(const std::string& list, int techniqueCount);

}  // namespace misalloc
