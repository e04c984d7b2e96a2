// What `simsoccer serve` prints at the end: each robot's command counters,
// the cameras' figures, the LoLA robots', the game, the GameController link
// and the final state.
#pragma once

#include <vector>

#include "simsoccer/match/lola_robots.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/game.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::apps {

void printCounters(const world::World& w, const net::SimServer& server);
void printCameraStats(const sim::Simulation& simulation);
void printGame(const referee::Game& g);
void printLolaResults(const std::vector<match::LolaResult>& results);
void printGameControllerLink(const referee::GameControllerLink& link);
// The world's final state hash and where the ball ended.
void printFinalState(const world::World& w);

}  // namespace simsoccer::apps
