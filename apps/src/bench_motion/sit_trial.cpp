// Sitting down and standing up: the robot walks at a seeded velocity for 2 s,
// is asked to sit for 5 s (the walk stops first), then to stand for 5 s.
#include <cmath>
#include <random>

#include "simsoccer/agents/motion/motion_controller.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {

// Success: on its feet throughout (upright, nothing but its feet on the
// carpet), the torso at least 5 cm lower when seated, back in the stance and
// standing as the referee counts it (World::isStanding) at the end. Seated, a
// robot may be lower than its fallen_torso_height: the K1's crouch (0.385 m)
// is, as is the squat a failed get-up leaves it in, which the referee must
// count as down.
SitResult sitTrial(const TrialContext& c, uint64_t seed) {
  world::Scenario s = emptyField(c);
  s.seed = seed;
  TrialWorld t(s, c);
  world::World& w = t.world;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  w.placeRobot(0, -3.0 + 0.5 * u(rng), 0.5 * u(rng), M_PI * u(rng));
  agents::MotionController motion = agents::loadMotionController(*w.robot(0).model, c.motions_dir);
  const double dt = t.dt();
  agents::MotionRequest request;
  request.kind = agents::MotionRequest::Kind::Walk;
  request.forward = 0.1 + 0.1 * u(rng);
  request.left = 0.05 * u(rng);
  request.turn = 0.3 * u(rng);
  t.driver.setControl([&](const world::World& world, std::span<float> p, std::span<float> k) {
    motion.update(dt, agents::motionSensors(world.sensorFrame(0)), request, p, k);
    return true;
  });
  const world::RobotInfo& robot = w.robot(0);
  const robots::RobotModel& model = *robot.model;
  const auto onItsFeet = [&] {
    if (w.torsoPose(0).linear()(2, 2) < std::cos(world::World::kFallenTilt)) return false;
    for (const engine::LinkContact& k : w.contacts())
      if (k.articulation == robot.body && !k.with_articulation && k.other_body < 0 &&
          k.link != model.legs[0].foot_link && k.link != model.legs[1].foot_link)
        return false;  // a knee, a hand or the seat on the carpet
    return true;
  };
  bool on_feet = true;
  double standing_height = 0.0;
  SitResult r;
  for (int i = 0; i < 1200; ++i) {
    if (i == 200) {
      standing_height = w.torsoPose(0).translation().z();
      request = agents::MotionRequest{};
      request.kind = agents::MotionRequest::Kind::Sit;
    }
    if (i == 700) {
      r.seated_height = w.torsoPose(0).translation().z();
      request = agents::MotionRequest{};
    }
    t.period();
    on_feet = on_feet && onItsFeet();
    if (i >= 700 && r.up_seconds < 0 && motion.state() == agents::MotionState::Stance)
      r.up_seconds = (i + 1 - 700) * dt;
  }
  r.falls = motion.counters().falls;
  r.success = on_feet && w.isStanding(0) && r.falls == 0 &&
              r.seated_height < standing_height - 0.05 && motion.counters().sits == 1 &&
              r.up_seconds >= 0;
  return r;
}

}  // namespace simsoccer::apps::motion
