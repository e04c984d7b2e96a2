#include "simsoccer/match/inprocess_agents.hpp"

#include "simsoccer/net/sim_server.hpp"

namespace simsoccer::match {

using namespace simsoccer::agents;

InProcessAgents::InProcessAgents(const world::World& world, const InProcessSetup& setup)
    : world_(world),
      position_(world.robotCount(), std::vector<float>(world::kActuators)),
      stiffness_(world.robotCount(), std::vector<float>(world::kActuators)) {
  if (!world.scenario().perception.enabled) {
    world::PerceptionSettings ps = world.scenario().perception;
    ps.enabled = true;
    own_perception_ = std::make_unique<world::PerceptionSystem>(world, ps);
  }
  const auto config = loadBehaviourConfig(setup.behaviour_config);
  for (world::RobotId r = 0; r < world.robotCount(); ++r) {
    const auto& info = world.robot(r);
    SoccerAgentSetup s;
    s.team = info.team;
    s.team_number = info.team + 1;
    s.player = info.number;
    s.role = r < setup.roles.size() ? setup.roles[r] : Role::Auto;
    s.seed = setup.seed * 131 + r;
    s.get_up = setup.get_up;
    agents_.push_back(
        std::make_unique<SoccerAgent>(*info.model, config, world.field(),
                                      motionsFolder(setup.motions_dir, *info.model), s));
  }
}

InProcessAgents::~InProcessAgents() = default;

void InProcessAgents::observe(const sim::Observation& o) {
  const double dt = world_.scenario().physics.control_period;
  const world::PerceptionSystem* perception = o.perception;
  if (!perception) {
    own_perception_->update(world_);
    perception = own_perception_.get();
  }
  simsoccer_msg_GameState game{};
  if (o.game) {
    // As an agent process gets it: the DDS message, budgets as the referee sets them.
    net::toMessage(*o.game, o.tick, game);
  }
  // Last period's team messages reach the sender's teammates now.
  for (const auto& [team, m] : outbox_)
    for (world::RobotId r = 0; r < world_.robotCount(); ++r)
      if (world_.robot(r).team == team && world_.robot(r).number != m.from_player)
        agents_[r]->receive(m, o.time);
  outbox_.clear();
  for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
    // The perception as an agent gets it: through the DDS message's conversion.
    simsoccer_msg_Perception msg{};
    net::toMessage(perception->perception(r), msg, scratch_);
    perceptionFromMessage(msg, o.tick, o.time, seen_);
    if (auto out = agents_[r]->step(o.time, dt, motionSensors(world_.sensorFrame(r)), &seen_,
                                    o.game ? &game : nullptr, position_[r], stiffness_[r])) {
      TeamMessageIn m;
      m.from_player = world_.robot(r).number;
      m.tick = o.tick;  // the period, as over DDS
      m.data = std::move(*out);
      outbox_.emplace_back(world_.robot(r).team, std::move(m));
    }
  }
}

void InProcessAgents::collect(uint64_t, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) {
  for (world::RobotId r = 0; r < world_.robotCount() && r < slots.size(); ++r)
    if (auto c = gate.check(r, std::span<const float>(position_[r]),
                            std::span<const float>(stiffness_[r])))
      slots[r] = {sim::Answer::Given, *c};
}

}  // namespace simsoccer::match
