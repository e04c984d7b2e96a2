// The built-in agents in this process, without DDS (benchmarks, learning):
// a command source of the period pipeline. Per robot the same
// agents::SoccerAgent an agent process runs, fed its SensorFrame and
// Perception as an agent process gets them, and answering with joint
// targets, which go through the simulation's CommandGate like any other
// source's. Two inputs differ from a match over DDS: the GameState's message
// budget is the referee's (DDS subtracts the messages relayed so far), and a
// teammate's message arrives in the next period (DDS relays it one period
// later still).
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/sim/command.hpp"
#include "simsoccer/world/perception.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::match {

struct InProcessSetup {
  std::vector<agents::Role> roles;  // one per robot (world order); missing: agents::Role::Auto
  uint64_t seed = 1;
  bool get_up = true;
  std::filesystem::path behaviour_config;  // configs/agents/soccer.yaml
  std::filesystem::path motions_dir;       // configs/motions
};

class InProcessAgents : public sim::CommandSource {
 public:
  // When the simulation has no perception (the scenario turns it off), the
  // agents see through their own, with the scenario's settings.
  InProcessAgents(const world::World& world, const InProcessSetup& setup);
  ~InProcessAgents() override;

  // Stage observe: every agent runs on the state of the tick.
  void observe(const sim::Observation& o) override;
  // Stage collect: the answers computed in observe, through the gate.
  void collect(uint64_t tick, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override;

  const agents::MotionController& motion(world::RobotId r) const { return agents_[r]->motion(); }
  const agents::SoccerBehaviour& behaviour(world::RobotId r) const { return agents_[r]->behaviour(); }

 private:
  const world::World& world_;
  std::unique_ptr<world::PerceptionSystem> own_perception_;  // when the simulation has none
  std::vector<std::unique_ptr<agents::SoccerAgent>> agents_;
  std::vector<std::pair<int, agents::TeamMessageIn>> outbox_;  // (team, message)
  std::vector<simsoccer_msg_PerceivedObject> scratch_;
  agents::PerceptionIn seen_;  // one robot's, as its agent gets it (reused)
  // Per robot, the answer computed in observe.
  std::vector<std::vector<float>> position_, stiffness_;
};

}  // namespace simsoccer::match
