// The goalkeeper against a ball rolled at its goal, in play and in the
// shoot-out.
#include <cmath>
#include <cstdio>
#include <random>

#include "cli.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {

// The goalkeeper behaviour on its line (team 0, own goal at -x) and a ball
// rolled at the goal from 2.5 m out (seeded: 1.6-2.4 m/s, at a point of the
// goal line inside the posts); 4 s to see whether it goes in. Saved: it did
// not, and the keeper touched it. In reach: aimed within the block's reach
// of the keeper's middle.
BlockResult blockTrial(const TrialContext& c, uint64_t seed, bool shootout, const BlockShot& shot) {
  world::Scenario s = emptyField(c);
  s.seed = seed;
  const fields::FieldModel f = fields::loadFieldModel(s.field_file);
  const auto config = agents::loadBehaviourConfig(c.bench.agents);
  // Where the behaviour's keeper stands.
  const double line =
      -f.halfLength() + (shootout ? config.shootout_keeper_line : config.keeper_line);
  s.robots[0].x = line;
  s.robots[0].y = 0.0;
  s.robots[0].yaw = 0.0;
  s.ball_position = {line + 2.5, 0.0, -1.0};
  TrialWorld t(s, c);
  world::World& w = t.world;
  t.addAgents({shootout ? agents::Role::PenaltyGoalkeeper : agents::Role::Goalkeeper}, seed);
  const double dt = w.scenario().physics.control_period;
  for (int i = 0; i < 200; ++i) {  // 2 s to settle into the stance
    t.period();
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  const double half_goal = 0.5 * f.goal.inner_width - f.ball.radius;
  const Vec3 from(line + 2.5, 0.6 * u(rng), f.ball.radius);
  Vec3 to(-f.halfLength(), half_goal * u(rng), f.ball.radius);
  double speed = 2.0 + 0.4 * u(rng);
  if (shot.offset) {  // aimed to pass the keeper's line there (it stands at y 0)
    const double k = (from.x() - line) / (from.x() - to.x());
    to.y() = from.y() + (*shot.offset - from.y()) / k;
  }
  if (shot.speed) speed = *shot.speed;
  engine::RigidBodyState b;
  b.pose.translation() = from;
  b.linear_velocity = speed * (to - from).normalized();
  b.angular_velocity = Vec3::UnitZ().cross(b.linear_velocity) / f.ball.radius;  // rolling
  w.setBallState(b);
  BlockResult r;
  // Where the ball would pass the keeper's line, from the keeper's middle;
  // its reach: the behaviour's (block, or in the shoot-out dive).
  const double y_at = from.y() + (to.y() - from.y()) * (from.x() - line) / (from.x() - to.x());
  r.in_reach = std::abs(y_at - w.torsoPose(0).translation().y()) <
               (shootout ? config.dive_reach : config.block_reach);
  for (int i = 0; i < 400; ++i) {
    t.period();
    if (c.verbose && i % 10 == 0)
      std::fprintf(stderr, "t %.2f %-10s ball %.2f %.2f torso z %.3f\n", i * dt,
                   agents::motionStateName(t.agents->motion(0).state()),
                   w.ballState().pose.translation().x(), w.ballState().pose.translation().y(),
                   w.torsoPose(0).translation().z());
    if (goalScored(w) == -1) break;
  }
  const auto& touch = w.lastBallTouch();
  r.saved = goalScored(w) == 0 && touch && touch->robot == 0;
  r.blocks = t.agents->motion(0).counters().blocks + t.agents->motion(0).counters().dives;
  r.falls = t.agents->motion(0).counters().falls;
  return r;
}

}  // namespace simsoccer::apps::motion
