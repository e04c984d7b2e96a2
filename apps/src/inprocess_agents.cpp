#include "inprocess_agents.hpp"

#include "cli.hpp"
#include "simsoccer/net/sim_server.hpp"

namespace simsoccer::apps {

InProcessAgents::InProcessAgents(world::World& world, const std::vector<agents::Role>& roles,
                                 uint64_t seed, bool get_up)
    : world_(world) {
  world::PerceptionSettings ps = world.scenario().perception;
  ps.enabled = true;
  perception_ = std::make_unique<world::PerceptionSystem>(world, ps);
  const auto config = agents::loadBehaviourConfig(findConfig("", "configs/agents/soccer.yaml"));
  const auto motions = findConfig("", "configs/motions");
  for (world::RobotId r = 0; r < world.robotCount(); ++r) {
    const auto& info = world.robot(r);
    agents::SoccerAgentSetup setup;
    setup.team = info.team;
    setup.team_number = info.team + 1;
    setup.player = info.number;
    setup.role = r < roles.size() ? roles[r] : agents::Role::Auto;
    setup.seed = seed * 131 + r;
    setup.get_up = get_up;
    agents_.push_back(
        std::make_unique<agents::SoccerAgent>(*info.model, config, world.field(), motions, setup));
  }
}

InProcessAgents::~InProcessAgents() = default;

void InProcessAgents::period(const simsoccer_msg_GameState* game) {
  const double dt = world_.scenario().physics.control_period;
  const double now = world_.time();
  perception_->update(world_);
  // Last period's team messages reach the sender's teammates now.
  for (const auto& [team, m] : outbox_)
    for (world::RobotId r = 0; r < world_.robotCount(); ++r)
      if (world_.robot(r).team == team && world_.robot(r).number != m.from_player)
        agents_[r]->receive(m, now);
  outbox_.clear();
  position_.resize(25);
  stiffness_.resize(25);
  for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
    // The perception as an agent gets it: through the DDS message's conversion.
    simsoccer_msg_Perception msg{};
    net::toMessage(perception_->perception(r), world_.robot(r).team, world_.robot(r).number, msg,
                   scratch_);
    const agents::PerceptionIn seen = agents::perceptionFromMessage(msg);
    if (auto out = agents_[r]->step(now, dt, agents::motionSensors(world_.sensorFrame(r)), &seen,
                                    game, position_, stiffness_)) {
      agents::TeamMessageIn m;
      m.from_player = world_.robot(r).number;
      m.tick = world_.controlTick();  // the period, as over DDS
      m.data = std::move(*out);
      outbox_.emplace_back(world_.robot(r).team, std::move(m));
    }
    world_.setCommand(r, std::span<const float>(position_), std::span<const float>(stiffness_));
  }
}

}  // namespace simsoccer::apps
