// simsoccer-agent --role: the soccer agent (behaviour and motion) answering each frame with
// the robot's perception, the game state and the teammates' messages.
#pragma once

#include <filesystem>
#include <memory>
#include <vector>

#include "cli.hpp"
#include "simsoccer/agents/agent_client.hpp"
#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::apps {

class SoccerPlayer {
 public:
  // From --role, --team-number, --seed, --no-get-up, --config and --field; a UsageError naming
  // the option for a bad one. The files load here, before the robot is claimed, so that a bad
  // one stops the agent before it plays.
  SoccerPlayer(const Options& opt, const robots::RobotModel& model,
               const std::filesystem::path& robot_motions, int team, int player);
  // Refuses the options that only --role uses when it is not given.
  static void refuseWithoutRole(const Options& opt);
  // Answers one frame on `client`; with `verbose`, the motion state and the behaviour's status
  // every 100 ticks on stderr.
  void answer(const simsoccer_msg_SensorFrame& frame, agents::AgentClient& client, bool verbose);

 private:
  int team_, player_;
  std::unique_ptr<agents::SoccerAgent> agent_;
  simsoccer_msg_GameState game_{};
  agents::PerceptionIn seen_;
  double last_time_ = 0.0;
  std::vector<float> position_, stiffness_;
};

}  // namespace simsoccer::apps
