// simsoccer-agent's --help text.
#pragma once

namespace simsoccer::apps {

extern const char* const kAgentHelp;

}  // namespace simsoccer::apps
