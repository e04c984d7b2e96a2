// The built-in agents run inside a bench process, without DDS: per robot the
// same agents::SoccerAgent an agent process runs, fed the same inputs (its
// SensorFrame and Perception, the GameState, teammates' messages one period
// late) and answering with joint targets only.
#pragma once

#include <memory>
#include <vector>

#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/world/perception.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::apps {

class InProcessAgents {
 public:
  // `roles`: one per robot (world order). The perception settings are the
  // scenario's if it turns perception on, else the ideal profile.
  InProcessAgents(world::World& world, const std::vector<agents::Role>& roles, uint64_t seed,
                  bool get_up = true);
  ~InProcessAgents();
  // One control period's agent work: perception, behaviour, motion, the
  // commands set on the world. Call before World::stepControlPeriod().
  void period(const simsoccer_msg_GameState* game = nullptr);
  const agents::MotionController& motion(world::RobotId r) const { return agents_[r]->motion(); }
  const agents::SoccerBehaviour& behaviour(world::RobotId r) const {
    return agents_[r]->behaviour();
  }

 private:
  world::World& world_;
  std::unique_ptr<world::PerceptionSystem> perception_;
  std::vector<std::unique_ptr<agents::SoccerAgent>> agents_;
  std::vector<std::pair<int, agents::TeamMessageIn>> outbox_;  // (team, message)
  std::vector<simsoccer_msg_PerceivedObject> scratch_;
  std::vector<float> position_, stiffness_;  // one robot's command, reused
};

}  // namespace simsoccer::apps
