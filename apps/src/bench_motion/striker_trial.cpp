// The striker alone: robot and ball at seeded random spots; up to `limit` s
// to score (the referee's goal rule).
#include <cmath>
#include <cstdio>
#include <random>

#include "cli.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {

// A striker alone (team 0, attacking +x): robot and ball at seeded random
// spots in the field; up to `limit` s to score.
StrikerResult strikerTrial(const TrialContext& c, uint64_t seed, double limit) {
  world::Scenario s = emptyField(c);
  s.seed = seed;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const fields::FieldModel field = fields::loadFieldModel(s.field_file);
  const double hl = field.halfLength() - 0.5, hw = field.halfWidth() - 0.5;
  s.robots[0].x = hl * u(rng);
  s.robots[0].y = hw * u(rng);
  s.robots[0].yaw = M_PI * u(rng);
  double bx = 0, by = 0;
  do {
    bx = (hl - 0.5) * u(rng);
    by = hw * u(rng);
  } while (std::hypot(bx - s.robots[0].x, by - s.robots[0].y) < 0.6);
  s.ball_position = {bx, by, -1.0};
  TrialWorld t(s, c);
  world::World& w = t.world;
  t.addAgents({agents::Role::Striker}, seed);
  StrikerResult r;
  const double dt = w.scenario().physics.control_period;
  for (int i = 0; i < static_cast<int>(limit / dt); ++i) {
    t.period();
    if (c.verbose && (i % 100 == 0 || (i < 150 && i % 10 == 0))) {
      // The true torso pose and ball beside what the striker believes.
      const world::Pose torso = w.torsoPose(0);
      const world::Vec3 ball = w.ballState().pose.translation();
      std::fprintf(stderr, "t %5.2f %-10s tilt %.2f true (%.2f %.2f %.2f) ball (%.2f %.2f) %s\n",
                   i * dt, agents::motionStateName(t.agents->motion(0).state()),
                   t.agents->motion(0).tilt(), torso.translation().x(), torso.translation().y(),
                   std::atan2(torso.linear()(1, 0), torso.linear()(0, 0)), ball.x(), ball.y(),
                   t.agents->behaviour(0).status().c_str());
    }
    if (goalScored(w) == 1) {
      r.scored = true;
      r.seconds = (i + 1) * dt;
      break;
    }
  }
  r.falls = t.agents->motion(0).counters().falls;
  return r;
}

}  // namespace simsoccer::apps::motion
