// A match's LoLA robots: the robots a team's robot binary drives instead of
// a built-in agent. Their LoLA sockets (lola::Endpoint) under the run's
// folder, their camera streams when the scenario's cameras are on, and with
// `lola.network` the field's network (a bridge and, per binary, a namespace
// made by `simsoccer lola-run --net`) on which the simulator broadcasts the
// GameController's packets, takes the robots' status packets and counts the
// team messages against the budget, as a GameController on a field does.
#pragma once

#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/lola/endpoint.hpp"
#include "simsoccer/lola/field_network.hpp"
#include "simsoccer/lola/image_stream.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"

namespace simsoccer::match {

// A LoLA robot's socket and what its clients did.
struct LolaResult {
  LolaPlayer player;
  std::filesystem::path socket;
  lola::RobotLolaStats stats;
  std::string address;  // on the field network (empty: none)
};

// Where a LoLA robot's socket is in a run's folder.
std::filesystem::path lolaSocketPath(const std::filesystem::path& out, const LolaPlayer& p);

class LolaRobots {
 public:
  // Joins `sim` (the endpoint as a command source, the cameras as an image
  // sink). `notice` hears the sockets, ports and addresses.
  LolaRobots(const MatchSession& session, sim::Simulation& sim, const std::filesystem::path& out,
             bool lockstep, const std::function<void(const std::string&)>& notice);
  ~LolaRobots();
  // After every period: the GameController's packets on the field network.
  void afterPeriod();
  lola::Endpoint& endpoint() { return *endpoint_; }
  std::vector<LolaResult> results() const;
  // The chest, left eye and right eye colours (RGB 0..255) robot r's client
  // set, for the match log and the video; none: not a LoLA robot, or no LEDs set yet.
  std::optional<std::array<uint8_t, 9>> leds(world::RobotId r) const;

 private:
  const MatchSession& session_;
  std::unique_ptr<lola::Endpoint> endpoint_;
  std::unique_ptr<lola::ImageStreams> images_;
  std::unique_ptr<lola::FieldBridge> bridge_;
  std::unique_ptr<referee::GameControllerLink> link_;
  std::unique_ptr<sim::FieldTeamMessages> team_messages_;
};

// The session's LoLA robots, or null when it has none.
std::unique_ptr<LolaRobots> openLolaRobots(const MatchSession& session, sim::Simulation& sim,
                                           const std::filesystem::path& out, bool lockstep,
                                           const std::function<void(const std::string&)>& notice);

}  // namespace simsoccer::match
