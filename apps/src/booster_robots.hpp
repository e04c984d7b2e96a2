// `serve --booster all|T:P,...`: robots served to Booster SDK clients (team
// code for a Booster K1), each on its own DDS domain from --booster-domain
// (default 0) up, in the order of the scenario's robots; with
// --booster-netns each in a network namespace of its own as domain 0.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"
#include "simsoccer/booster/endpoint.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::apps {

// "T:P": the scenario's team (0, 1) and a player number; throws UsageError
// naming `option`.
std::pair<int, int> parseTeamPlayer(const std::string& item, const std::string& option);

// The robots --booster names (empty without the option): "all", or T:P with
// T the scenario's team (0, 1) and P the player number.
std::vector<world::RobotId> boosterRobots(const Options& opt, const world::World& w);

// The network namespace `serve --booster-netns` serves robot T:P in (and
// `booster-run --robot T:P` runs a team binary in).
std::string boosterNamespace(int team, int player);

// The robots' endpoint, added to the simulation, and with --booster-netns
// their network namespaces (removed when this goes); prints where each
// robot is served.
struct BoosterRobots {
  std::vector<std::string> namespaces;  // made here, removed in the destructor
  std::unique_ptr<booster::Endpoint> endpoint;
  BoosterRobots() = default;
  BoosterRobots(const BoosterRobots&) = delete;
  BoosterRobots& operator=(const BoosterRobots&) = delete;
  ~BoosterRobots();
};
// `answer_timeout`: lockstep's wait for a LowCmd (s), unless --timeout.
std::unique_ptr<BoosterRobots> openBoosterRobots(const Options& opt, const world::World& w,
                                                 sim::Simulation& simulation,
                                                 const std::vector<world::RobotId>& robots,
                                                 const std::filesystem::path& dds_config,
                                                 double answer_timeout);

// Delivers the camera images still queued when it goes, before the image
// sinks (transports declared before it) go.
struct FlushCamerasOnExit {
  sim::Simulation& simulation;
  ~FlushCamerasOnExit() { simulation.flushCameras(); }
};

void printBoosterStats(const BoosterRobots& robots, const world::World& w);

}  // namespace simsoccer::apps
