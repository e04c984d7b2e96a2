// The --help texts of match, penalty, serve and bench scaling. kMatchHelp has one %s: the
// default mode.
#pragma once

namespace simsoccer::apps {

extern const char* const kMatchHelp;
extern const char* const kPenaltyHelp;
extern const char* const kServeHelp;
extern const char* const kBenchScalingHelp;

}  // namespace simsoccer::apps
