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
  const std::string motions = findConfig("", "configs/motions").string();
  agents::FallDetectorParameters fall;
  fall.get_up = get_up;
  for (world::RobotId r = 0; r < world.robotCount(); ++r) {
    const auto& info = world.robot(r);
    Agent a;
    a.motion = std::make_unique<agents::MotionController>(
        *info.model, agents::loadKeyframeMotion(motions + "/get_up_front.yaml", *info.model),
        agents::loadKeyframeMotion(motions + "/get_up_back.yaml", *info.model),
        agents::WalkParameters{}, agents::KickParameters{}, fall);
    a.behaviour = std::make_unique<agents::SoccerBehaviour>(
        config, world.field(), info.team, info.team + 1, info.number,
        r < roles.size() ? roles[r] : agents::Role::Auto, seed * 131 + r);
    agents_.push_back(std::move(a));
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
        agents_[r].behaviour->receive(m, now);
  outbox_.clear();
  std::vector<float> position(25), stiffness(25);
  std::vector<double> p(25), k(25);
  for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
    Agent& a = agents_[r];
    simsoccer_msg_Perception msg{};
    net::toMessage(perception_->perception(r), world_.robot(r).team, world_.robot(r).number, msg,
                   scratch_);
    const agents::PerceptionIn seen = agents::perceptionFromMessage(msg);
    agents::SoccerBehaviour::Input in;
    in.time = now;
    in.perception = &seen;
    in.game = game;
    in.motion = a.motion->state();
    in.fallen = a.motion->state() == agents::MotionState::Falling ||
                a.motion->state() == agents::MotionState::Lying ||
                a.motion->state() == agents::MotionState::GettingUp;
    const agents::MotionRequest request = a.behaviour->update(in);
    if (a.behaviour->takeMotionRestart()) a.motion->restart();
    if (auto out = a.behaviour->outgoing(in)) {
      agents::TeamMessageIn m;
      m.from_player = world_.robot(r).number;
      m.tick = world_.stepCount();
      m.data = *out;
      outbox_.emplace_back(world_.robot(r).team, std::move(m));
    }
    a.motion->update(dt, agents::motionSensors(world_.sensorFrame(r)), request, position,
                     stiffness);
    for (size_t i = 0; i < 25; ++i) {
      p[i] = position[i];
      k[i] = stiffness[i];
    }
    world_.setCommand(r, p, k);
  }
}

}  // namespace simsoccer::apps
