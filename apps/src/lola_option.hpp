// The `--lola T:P,...` and `--lola-net` options of match and serve: robots a
// team's binary drives through LoLA instead of a built-in agent, and the
// field's network for those binaries.
#pragma once

#include "cli.hpp"
#include "simsoccer/match/match_session.hpp"

namespace simsoccer::apps {

inline void addLolaRobots(const Options& opt, match::MatchConfig& config) {
  if (opt.flag("lola-net")) config.lola.network = true;
  if (opt.has("lola")) {
    try {
      const auto players = match::parseLolaPlayers(opt.get("lola", ""));
      config.lola.robots.insert(config.lola.robots.end(), players.begin(), players.end());
      config.lola.from_option = players.size();
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--lola: ") + e.what());
    }
  }
  if (opt.flag("lola-net") && config.lola.robots.empty())
    throw UsageError("--lola-net: no LoLA robots (--lola T:P,... or the config's lola.robots)");
}

}  // namespace simsoccer::apps
