// The table of `simsoccer bench motion`, and its one-trial tuning modes.
#pragma once

#include <cstdint>
#include <optional>

#include "cli.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {

// Runs every trial of the table (trial counts and the random walk's minutes
// from the options), prints it and writes --csv; returns the exit status.
int printMotionTable(const TrialContext& c, const Options& opt, uint64_t seed);

// The one trial the options ask for (--get-up, --striker, --block, --penalty, --kick, --random,
// --vx/--vy/--turn), printed on one line; its exit status, or none when the options ask for
// the table.
std::optional<int> runSingleTrial(const TrialContext& c, const Options& opt, uint64_t seed);

}  // namespace simsoccer::apps::motion
