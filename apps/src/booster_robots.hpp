// `serve --booster all|T:P,...`: robots served to Booster SDK clients (team
// code for a Booster K1), each on its own DDS domain from --booster-domain
// (default 0) up, in the order of the scenario's robots; with
// --booster-netns each in a network namespace of its own as domain 0, on a
// field network where the GameController's packets reach it.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "cli.hpp"
#include "simsoccer/booster/endpoint.hpp"
#include "simsoccer/lola/field_network.hpp"
#include "simsoccer/net/domain_claim.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::apps {

// The robots --booster names (empty without the option): "all", or T:P
// with T a GameController team number (`team_numbers`: the scenario's team
// 0 and 1; a match config's, or --teams, default 1 and 2) and P the player.
std::vector<world::RobotId> boosterRobots(const Options& opt, const world::World& w,
                                          const std::array<int, 2>& team_numbers);

// The field network of `serve --booster-netns` (as LoLA's, its own bridge
// and addresses); `booster-run --robot T:P` finds a robot's namespace in it.
lola::FieldNetwork boosterFieldNetwork();

// The robots' endpoint, added to the simulation, and with --booster-netns
// the field network: a bridge and a namespace per robot (PREFIX.T.P on the
// bridge, loopback inside) where its domain shows as domain 0; removed when
// this goes. Prints where each robot is served.
struct BoosterRobots {
  // The Booster SDK domains served here, claimed on this host (none in namespaces: each
  // namespace's domain 0 is its own); released after the endpoint.
  std::vector<net::DomainClaim> domains;
  std::unique_ptr<lola::FieldBridge> bridge;
  std::vector<std::unique_ptr<lola::RobotNamespace>> namespaces;
  std::unique_ptr<booster::Endpoint> endpoint;
  std::vector<std::string> names;  // "T:P" (GameController team number:player), per robot
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
                                                 double answer_timeout,
                                                 const std::array<int, 2>& team_numbers);

// Delivers the camera images still queued when it goes, before the image
// sinks (transports declared before it) go.
struct FlushCamerasOnExit {
  sim::Simulation& simulation;
  ~FlushCamerasOnExit() { simulation.flushCameras(); }
};

void printBoosterStats(const BoosterRobots& robots);

}  // namespace simsoccer::apps
