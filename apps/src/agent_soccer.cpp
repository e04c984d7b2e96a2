#include "agent_soccer.hpp"

#include <cstdio>
#include <string>

#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::apps {

SoccerPlayer::SoccerPlayer(const Options& opt, const robots::RobotModel& model,
                           const std::filesystem::path& robot_motions, int team, int player)
    : team_(team),
      player_(player),
      position_(protocol::kActuators, 0.0f),
      stiffness_(protocol::kActuators, 1.0f) {
  const auto role = agents::roleFromName(opt.get("role", ""));
  if (!role)
    throw UsageError(
        "--role must be auto, striker, supporter, defender, goalkeeper, penalty-kicker or "
        "penalty-goalkeeper");
  agents::SoccerAgentSetup setup;
  setup.team = team;
  setup.team_number = opt.wholeNumber("team-number", team + 1, 0, 254);
  setup.player = player;
  setup.role = *role;
  setup.seed = opt.seed("seed", 1);
  setup.get_up = !opt.flag("no-get-up");
  agent_ = std::make_unique<agents::SoccerAgent>(
      model,
      agents::loadBehaviourConfig(findConfig(opt.get("config", ""), "configs/agents/soccer.yaml")),
      fields::loadFieldModel(findConfig(opt.get("field", ""), "fields/spl.yaml")), robot_motions,
      setup);
}

void SoccerPlayer::refuseWithoutRole(const Options& opt) {
  if (opt.has("role")) return;
  for (const char* soccer_only : {"seed", "config", "team-number"})
    if (opt.has(soccer_only))
      throw UsageError(std::string("--") + soccer_only + " goes with --role");
  if (opt.flag("no-get-up")) throw UsageError("--no-get-up goes with --role");
}

void SoccerPlayer::answer(const simsoccer_msg_SensorFrame& frame, agents::AgentClient& client,
                          bool verbose) {
  // This tick's perception (in the frame), the game, teammates' messages, then behaviour and
  // motion.
  const double dt = last_time_ > 0 ? frame.sim_time - last_time_ : 0.01;
  last_time_ = frame.sim_time;
  const bool have_seen = agents::perceptionFromFrame(frame, seen_);
  const bool have_game = client.gameState(game_);
  for (const auto& m : client.receiveTeamMessages()) agent_->receive(m, frame.sim_time);
  if (auto out = agent_->step(frame.sim_time, dt > 0 ? dt : 0.01, agents::motionSensors(frame),
                              have_seen ? &seen_ : nullptr, have_game ? &game_ : nullptr, position_,
                              stiffness_))
    client.sendTeamMessage(*out);
  if (verbose && frame.tick % 100 == 0)
    std::fprintf(stderr, "agent %d/%d t %.1f %s %s\n", team_, player_, frame.sim_time,
                 agents::motionStateName(agent_->motion().state()),
                 agent_->behaviour().status().c_str());
  client.send(frame.tick, position_, stiffness_);
}

}  // namespace simsoccer::apps
