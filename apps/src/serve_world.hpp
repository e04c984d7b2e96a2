// What `simsoccer serve` runs: a whole match's world and officials (a match config), or a
// scenario's world with the officials of --rules, or with none.
#pragma once

#include <array>
#include <filesystem>
#include <memory>
#include <optional>

#include "cli.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/net/sim_server.hpp"

namespace simsoccer::apps {

struct ServedWorld {
  std::unique_ptr<match::MatchSession> session;  // a match config's
  std::unique_ptr<world::World> own_world;       // a scenario's
  std::unique_ptr<sim::GameOfficials> own_officials;
  sim::GameOfficials* officials = nullptr;  // the session's or own_officials; null: none
  std::array<int, 2> team_numbers{1, 2};    // GameController numbers of teams 0 and 1
  world::World& world() { return session ? session->world() : *own_world; }
};

// Builds it from `file` and the options (--rules, --teams, --auto-placement, --half, --lola,
// --seed); a match config also sets the server's timeout and team-message delay and loss.
ServedWorld openServedWorld(const Options& opt, const std::filesystem::path& file,
                            std::optional<uint16_t> external_gc, net::ServerConfig& cfg);

}  // namespace simsoccer::apps
