// What `simsoccer serve` prints at the end: each robot's command counters,
// the cameras' figures and the game.
#pragma once

#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/game.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::apps {

void printCounters(const world::World& w, const net::SimServer& server);
void printCameraStats(const sim::Simulation& simulation);
void printGame(const referee::Game& g);

}  // namespace simsoccer::apps
