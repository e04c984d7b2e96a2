// A penalty kick: the kicker behaviour against the goalkeeper behaviour.
#include <cmath>
#include <cstdio>
#include <random>

#include "cli.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "trial.hpp"

namespace simsoccer::apps::motion {

// One penalty: kicker (team 0) behind the ball on the +x penalty mark,
// keeper (team 1) on that goal line; ends on a goal, the ball out or stopped
// after the kick, or after `limit` s.
PenaltyOutcome penaltyTrial(const TrialContext& c, uint64_t seed, double limit) {
  world::Scenario s = emptyField(c);
  s.seed = seed;
  const fields::FieldModel f = fields::loadFieldModel(s.field_file);
  const double mark = f.halfLength() - f.penalty_mark_distance.value_or(1.3);
  s.robots[0].x = mark - 0.5;
  s.robots[0].y = 0.0;
  s.robots[0].yaw = 0.0;
  world::RobotPlacement keeper;
  keeper.team = 1;
  keeper.x = f.halfLength() - 0.05;
  keeper.yaw = M_PI;
  s.robots.push_back(keeper);
  s.ball_position = {mark, 0.0, -1.0};
  // Both robots see as in configs/scenarios/penalty.yaml: with the realistic
  // profile's noise, misses and false balls.
  s.perception.realistic = true;
  TrialWorld t(s, c);
  world::World& w = t.world;
  t.addAgents({agents::Role::PenaltyKicker, agents::Role::PenaltyGoalkeeper}, seed);
  const double dt = w.scenario().physics.control_period;
  bool kicked = false;
  double still = 0.0;
  for (int i = 0; i < static_cast<int>(limit / dt); ++i) {
    t.period();
    if (c.verbose && i % 100 == 0)
      std::fprintf(stderr, "t %5.1f kicker %s | keeper %s\n", i * dt,
                   t.agents->behaviour(0).status().c_str(),
                   t.agents->behaviour(1).status().c_str());
    const auto ball = w.ballState();
    if (goalScored(w) == 1) return PenaltyOutcome::Goal;
    const Vec3 b = ball.pose.translation();
    if (!kicked && std::hypot(b.x() - mark, b.y()) > 0.05) kicked = true;
    // The keeper down before the kick: a goal (the referee's shoot-out rule).
    if (!kicked && !w.isStanding(1)) return PenaltyOutcome::Goal;
    if (!kicked) continue;
    // Wholly over the goal line outside the goal, or over the touchline: missed.
    // (The goal line as the referee's goal rule draws it: its far edge.)
    if (b.x() > f.halfLength() + 0.5 * f.line_width + f.ball.radius ||
        std::abs(b.y()) > f.halfWidth())
      return PenaltyOutcome::Missed;
    still = ball.linear_velocity.norm() < 0.02 ? still + dt : 0.0;
    if (still > 0.5) {
      // Stopped in play: the keeper's (touched, or it came to rest before the line).
      const auto& touch = w.lastBallTouch();
      return touch && touch->robot == 1 ? PenaltyOutcome::Saved : PenaltyOutcome::Missed;
    }
  }
  return PenaltyOutcome::Timeout;
}

}  // namespace simsoccer::apps::motion
