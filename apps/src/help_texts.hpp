// The --help texts of match, penalty and serve. kMatchHelp has one %s: the default mode.
#pragma once

namespace simsoccer::apps {

extern const char* const kMatchHelp;
extern const char* const kPenaltyHelp;
extern const char* const kServeHelp;

}  // namespace simsoccer::apps
