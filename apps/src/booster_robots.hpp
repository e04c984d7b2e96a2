// `serve --booster all|T:P,...`: robots served to Booster SDK clients (team
// code for a Booster K1), each on its own DDS domain from --booster-domain
// (default 0) up, in the order of the scenario's robots.
#pragma once

#include <memory>
#include <vector>

#include "cli.hpp"
#include "simsoccer/booster/endpoint.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::apps {

// The robots --booster names (empty without the option): "all", or T:P with
// T the scenario's team (0, 1) and P the player number.
std::vector<world::RobotId> boosterRobots(const Options& opt, const world::World& w);

// Joins each robot's domain and adds the endpoint to the simulation; prints
// which domain serves which robot.
std::unique_ptr<booster::Endpoint> openBoosterRobots(const Options& opt, const world::World& w,
                                                     sim::Simulation& simulation,
                                                     const std::vector<world::RobotId>& robots,
                                                     const std::filesystem::path& dds_config);

void printBoosterStats(const booster::Endpoint& endpoint, const world::World& w);

}  // namespace simsoccer::apps
