// simsoccer-agent without --role: the simple modes (stand and nod, walk at a
// velocity) and the test modes (malformed commands, stopping to answer).
#pragma once

#include <string>
#include <vector>

#include "simsoccer/agents/agent_client.hpp"
#include "simsoccer/agents/motion/walk_engine.hpp"
#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::apps {

class SimpleModes {
 public:
  // mode: nod, walk, garbage or stall; (vx, vy, turn): the walk's velocity; `motions`: the
  // robot's motions folder (its gait.yaml, where it has one).
  SimpleModes(const robots::RobotModel& model, const std::filesystem::path& motions,
              std::string mode, double vx, double vy, double turn);
  // Answers one frame on `client` (garbage: an invalid command first).
  void answer(const simsoccer_msg_SensorFrame& frame, agents::AgentClient& client, int team,
              int player);

 private:
  const robots::RobotModel& model_;
  std::string mode_;
  double vx_, vy_, turn_;
  std::vector<float> position_, stiffness_;
  int head_pitch_ = -1;  // actuator index
  agents::WalkEngine walk_;
  std::vector<double> targets_;  // the walk's, body joint order
  double start_time_ = -1.0, last_time_ = 0.0;
  long garbage_ = 0;
};

}  // namespace simsoccer::apps
