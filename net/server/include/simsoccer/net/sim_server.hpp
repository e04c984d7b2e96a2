// The DDS transport of the simulation: a command source of the period
// pipeline (sim::Simulation) that publishes every robot's SensorFrame (with
// its perception), camera images, status and team messages, and takes the
// agents' JointCommands, keeps robot ownership, and relays team messages on
// simulated time. Lockstep: collect waits for every owned robot's answer to
// the tick it published (up to the timeout); real time: the latest answer.
// Perception and cameras belong to the simulation; this only sends them.
//
// Topics (names, QoS, rates and sizes: docs/protocol.md):
//   simsoccer_SensorFrame   sim -> agent, partition robot_<team>_<player> (with perception)
//   simsoccer_JointCommand  agent -> sim
//   simsoccer_JoinRequest   agent -> sim
//   simsoccer_RobotStatus   sim -> agent, partition robot_<team>_<player>
//   simsoccer_SimClock      sim -> agents
//   simsoccer_GameState     sim -> agents
//   simsoccer_TeamMessageSend    agent -> sim
//   simsoccer_TeamMessageDeliver sim -> agent, partition robot_<team>_<to>
//   simsoccer_WorldTruth    sim -> monitors (optional)
//   simsoccer_CameraImage   sim -> agent, partition robot_<team>_<player> (cameras on)
#pragma once

#include <array>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <vector>

#include "simsoccer/net/dds.hpp"
#include "simsoccer/net/robot_keys.hpp"
#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/camera_system.hpp"
#include "simsoccer/world/perception.hpp"
#include "simsoccer/world/world.hpp"
#include "simsoccer_msgs.h"

namespace simsoccer::net {

struct ServerConfig {
  DomainConfig dds;
  bool lockstep = true;
  double command_timeout = 0.5;     // s of wall time to wait per lockstep period
  bool hold_on_release = true;      // a released robot holds its pose (false: goes limp)
  double team_message_delay = 0.0;  // s of simulated time (at least one control period)
  double team_message_loss = 0.0;   // probability a copy is lost
  bool world_truth = false;
  // Robots another transport drives (LoLA): claims and commands for them are ignored.
  std::vector<world::RobotId> not_served;
  // Reserved robots: a claim must prove it holds its robot's key
  // (robotKey(secret, team, player)), also after the owner went away; the
  // owner's status proves the simulator holds it too (robot_keys.hpp).
  // Empty: the first claimant owns a free robot.
  std::optional<MatchSecret> reserve;
  // Told, once per robot, when its owner's command is refused and why: a driver whose every
  // command is refused (built for another robot model, say) leaves its robot holding and, in
  // lockstep, each period waiting its timeout. Empty: not told (the counters still count).
  std::function<void(const std::string&)> notice;
};

// accepted, missed: the simulation's count (sim::CommandStats); rejected:
// the gate's refusals and answers to the wrong tick; refused: samples from a
// participant that does not own the robot; unauthorised: of those, claims
// of a reserved robot without its key's proof.
struct RobotNetStats {
  bool owned = false;
  uint64_t accepted = 0, rejected = 0, refused = 0, missed = 0, unauthorised = 0;
};

class SimServer : public sim::CommandSource {
 public:
  // Joins `sim` as a command source (and an image sink when cameras are on).
  SimServer(sim::Simulation& sim, const ServerConfig& config);
  ~SimServer() override;

  // The period's stages (sim::CommandSource): publish the frames for the
  // tick, collect the owned robots' answers to it, status after the step.
  void observe(const sim::Observation& o) override;
  void collect(uint64_t tick, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override;
  void afterStep(const world::World& world) override;
  // Handle claims and commands for up to `seconds` of wall time without
  // stepping (while agents connect).
  void poll(double seconds);
  // Polls until `count` robots are owned, and every owned robot's frame
  // writer has matched its agent's reader (a frame published before that
  // match is lost, and in lockstep the agent would never answer it), or
  // until the timeout passes.
  bool waitForOwners(size_t count, double timeout_seconds);

  size_t ownedCount() const;
  RobotNetStats stats(world::RobotId r) const;
  // Frees robot r now, as its owner's lease running out would (it holds its
  // pose or goes limp, and lockstep stops waiting for it): for a launcher
  // that saw the owner's process exit, which says nothing on DDS when it
  // crashed. False if nobody owned it.
  bool releaseRobot(world::RobotId r);
  // Team messages of `team` (index) relayed so far (each sent message once).
  uint64_t teamMessagesSent(int team) const override { return team_messages_[team == 0 ? 0 : 1]; }
  // The GameState published at every change and every 0.5 s (2 Hz); none is
  // published until one is set (a simulator without a referee).
  void setGameState(const simsoccer_msg_GameState& state);
  // The referee's state, published when it changed (and at 2 Hz); the
  // officials count the team messages relayed against the budget.
  // `left_team`: the team index that teams[0] describes (Game::leftTeam()).
  void publishGameState(referee::ControlData data, int left_team);

 private:
  struct Impl;
  std::array<uint64_t, 2> team_messages_{};
  std::optional<referee::ControlData> published_game_;
  struct RobotSlot {
    int team = 0, player = 0;
    RobotNetStats stats;
    dds_guid_t owner{};
    std::optional<RobotKey> key;           // reserved: only a claim proving this key
    dds_instance_handle_t owner_join = 0;  // the owner's JoinRequest writer (liveness)
    bool has_command = false;              // a checked command waits to be taken
    uint64_t last_tick = 0;                // tick of the last accepted command
    uint64_t wrong_tick = 0;               // answers to a tick other than the one asked
    bool told_refused = false;             // config_.notice told of a refused command
    sim::RobotCommand command;             // checked and quantised by the gate
  };

  void handleJoins();
  // Takes and checks the waiting commands; called from the DDS listener
  // (the receive thread) and from poll(), always with mutex_ held.
  void handleCommands();
  bool allOwnedAnswered() const;
  static void onCommands(dds_entity_t reader, void* self);
  void checkOwners();
  void relayTeamMessages(uint64_t tick);
  void publishStatus(world::RobotId r);
  void publishTruth(uint64_t tick);
  void release(world::RobotId r);
  int robotIndex(int team, int player) const;

  sim::Simulation& sim_;
  world::World& world_;
  ServerConfig config_;
  // Guards robots_ between the main thread and the command listener.
  mutable std::mutex mutex_;
  std::condition_variable answered_;
  uint64_t expected_tick_ = UINT64_MAX;  // lockstep: the tick commands must answer
  const uint64_t ticks_per_second_;      // control periods per simulated second
  uint64_t published_tick_ = 0;          // the newest tick whose frames went out
  std::unique_ptr<Impl> impl_;
  std::vector<RobotSlot> robots_;
};

// The referee's GameController packet as the DDS GameState message.
void toMessage(const referee::ControlData& d, uint64_t tick, simsoccer_msg_GameState& m);

// A robot's perception as its SensorFrame carries it (`m.robots` points into
// `scratch`; the tick and time are the frame's).
void toMessage(const world::Perception& p, simsoccer_msg_Perception& m,
               std::vector<simsoccer_msg_PerceivedObject>& scratch);

// A camera image as the wire message (`m.data` points into `image.data`).
void toMessage(const world::CameraImage& image, simsoccer_msg_CameraImage& m);

// Copies a world sensor frame into the wire message.
void toMessage(const world::SensorFrame& f, int team, int player, simsoccer_msg_SensorFrame& m);

}  // namespace simsoccer::net
