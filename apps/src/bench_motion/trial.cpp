#include "trial.hpp"

#include <algorithm>

#include "cli.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/referee/referee.hpp"
#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::apps::motion {

MotionBench loadMotionBench(const std::filesystem::path& file) {
  const engine::ConfigNode root = engine::ConfigNode::loadFile(file);
  root.allowOnly({"robot_model", "field", "motions", "agents", "targets", "random_commands"});
  MotionBench b;
  const auto path = [&](const char* key) {
    const std::filesystem::path p = engine::resolveBeside(root.file(), root[key].string());
    if (!std::filesystem::exists(p)) root[key].fail("no such file or folder: " + p.string());
    return p;
  };
  b.robot_model = path("robot_model");
  b.field = path("field");
  b.motions = path("motions");
  b.agents = path("agents");
  b.robot = robots::loadRobotModel(b.robot_model).name;
  const engine::ConfigNode t = root["targets"];
  t.allowOnly({"walk_forward", "walk_sideways", "turn", "kick_distance"});
  b.walk_forward = t["walk_forward"].positive();
  b.walk_sideways = t["walk_sideways"].positive();
  b.turn = t["turn"].positive();
  b.kick_distance = t["kick_distance"].positive();
  const engine::ConfigNode r = root["random_commands"];
  r.allowOnly({"forward", "sideways", "turn"});
  const auto range = [&](const char* key) {
    const std::vector<double> v = r[key].numbers(2);
    if (!(v[0] <= v[1])) r[key].fail("expected [lowest, highest]");
    return std::array<double, 2>{v[0], v[1]};
  };
  b.random_forward = range("forward");
  b.random_sideways = range("sideways");
  b.random_turn = range("turn");
  return b;
}

world::Scenario emptyField(const TrialContext& c) {
  world::Scenario s;
  s.name = "bench_motion";
  s.field_file = c.bench.field;
  s.robot_model_file = c.bench.robot_model;
  s.ball_position = {4.0, 2.5, -1.0};
  world::RobotPlacement p;
  p.x = -3.0;
  s.robots.push_back(p);
  return s;
}

void DriverSource::observe(const sim::Observation& o) {
  has_ = control_ && control_(*o.world, position_, stiffness_);
}

void DriverSource::collect(uint64_t, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) {
  if (!has_) return;
  if (auto c = gate.check(0, std::span<const float>(position_), std::span<const float>(stiffness_)))
    slots[0] = {sim::Answer::Given, *c};
}

namespace {
sim::SimulationConfig simulationConfig(sim::Mode mode) {
  sim::SimulationConfig c;
  c.mode = mode;
  return c;
}

world::Scenario withTiming(world::Scenario s, const TrialContext& c) {
  if (c.dt > 0) s.physics.dt = c.dt;
  if (c.control_period > 0) s.physics.control_period = c.control_period;
  if (c.joint_sweeps > 0) s.physics.joint_sweeps = c.joint_sweeps;
  return s;
}
}  // namespace

TrialWorld::TrialWorld(const world::Scenario& scenario, const TrialContext& context)
    : world(withTiming(scenario, context)),
      simulation(world, simulationConfig(context.mode)),
      context_(context) {
  simulation.addSource(driver);
}

void TrialWorld::addAgents(std::vector<agents::Role> roles, uint64_t seed) {
  agents = std::make_unique<match::InProcessAgents>(
      world, match::InProcessSetup{std::move(roles), seed, true, context_.bench.agents,
                                   context_.motions_dir});
  simulation.addSource(*agents);
}

void bodyTargetsToCommand(const robots::RobotModel& model, const std::vector<double>& targets,
                          double stiffness, std::span<float> position,
                          std::span<float> stiffness_out) {
  // Zeroed first, then filled: one loop that zeroes both arrays and then
  // conditionally overwrites them is miscompiled by Debian 12's GCC 12.2 at
  // -O3 (its loop distribution moves the second array's zeroing after the
  // conditional store: every stiffness came out 0).
  std::fill(position.begin(), position.end(), 0.0f);
  std::fill(stiffness_out.begin(), stiffness_out.end(), 0.0f);
  const size_t n = std::min({position.size(), stiffness_out.size(), model.actuators.size()});
  for (size_t a = 0; a < n; ++a) {
    const robots::Actuator& actuator = model.actuators[a];
    if (actuator.kind != robots::Actuator::Kind::Joint) continue;
    position[a] = static_cast<float>(targets.at(static_cast<size_t>(actuator.index)));
    stiffness_out[a] = static_cast<float>(stiffness);
  }
}

void walkPeriod(const world::World& world, agents::WalkEngine& engine, double dt,
                std::vector<double>& targets, std::span<float> position,
                std::span<float> stiffness) {
  const auto& f = world.sensorFrame(0);
  engine.update(dt,
                {Vec3(f.gyroscope[0], f.gyroscope[1], f.gyroscope[2]), f.angles[0], f.angles[2]},
                targets);
  bodyTargetsToCommand(*world.robot(0).model, targets, 1.0, position, stiffness);
}

void settleIntoStance(TrialWorld& t, agents::WalkEngine& engine, std::vector<double>& targets) {
  const auto& model = *t.world.robot(0).model;
  const std::vector<double>& stand = model.pose("stand");
  int i = 0;
  t.driver.setControl([&](const world::World&, std::span<float> p, std::span<float> k) {
    engine.easeIn(stand, i * t.dt(), targets);
    bodyTargetsToCommand(model, targets, 1.0, p, k);
    return true;
  });
  for (i = 0; i < 100; ++i) t.period();
  t.driver.setControl({});  // its captures end here
}

int goalScored(const world::World& w) {
  return referee::ballInGoal(w.field(), w.ballState().pose.translation());
}

const char* penaltyOutcomeName(PenaltyOutcome o) {
  switch (o) {
    case PenaltyOutcome::Goal:
      return "goal";
    case PenaltyOutcome::Saved:
      return "saved";
    case PenaltyOutcome::Missed:
      return "missed";
    case PenaltyOutcome::Timeout:
      return "timeout";
  }
  return "?";
}

}  // namespace simsoccer::apps::motion
