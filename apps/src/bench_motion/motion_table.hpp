// The table of `simsoccer bench motion`.
#pragma once

#include <cstdint>

#include "cli.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {

// Runs every trial of the table (trial counts and the random walk's minutes
// from the options), prints it and writes --csv; returns the exit status.
int printMotionTable(const TrialContext& c, const Options& opt, uint64_t seed);

}  // namespace simsoccer::apps::motion
