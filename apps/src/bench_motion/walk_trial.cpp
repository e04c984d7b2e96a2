// Walking: the walk engine alone at a commanded velocity (or a schedule of
// them), from the stand pose eased into the walk's stance.
#include <array>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "trial.hpp"

namespace simsoccer::apps::motion {
WalkResult walkTrial(const TrialContext& c, const Schedule& schedule, double seconds, int* falls,
                     const StandSchedule& stands) {
  TrialWorld t(emptyField(c), c);
  world::World& w = t.world;
  const auto& model = *w.robot(0).model;
  agents::WalkEngine engine(model, c.walk);
  std::vector<double> targets = model.pose("stand");
  const double dt = t.dt();
  settleIntoStance(t, engine, targets);
  if (falls) {
    // Random walking: the ball in a corner, outside where the robot walks (below).
    engine::RigidBodyState ball;
    ball.pose.translation() =
        Vec3(w.field().halfLength() - 0.3, w.field().halfWidth() - 0.3, w.field().ball.radius);
    w.setBallState(ball);
  }
  const engine::Pose start = w.torsoPose(0);
  const Eigen::Vector3d first = schedule(0.0);
  const double vx = first.x(), vy = first.y();
  WalkResult r;
  const long periods = static_cast<long>(seconds / dt);
  long i = 0;
  const auto walkControl = [&](const world::World& world, std::span<float> p, std::span<float> k) {
    const double now = static_cast<double>(i) * dt;
    const Eigen::Vector3d v = schedule(now);
    if (stands && stands(now))
      engine.stop();
    else
      engine.setVelocity(v.x(), v.y(), v.z());
    walkPeriod(world, engine, dt, targets, p, k);
    return true;
  };
  t.driver.setControl(walkControl);
  // The torso's heading (yaw about the field's z).
  const auto headingOf = [](const engine::Pose& p) {
    return std::atan2(p.linear()(1, 0), p.linear()(0, 0));
  };
  // Puts the robot on its feet at (x, y), facing as it does now, and eases it into the walk's
  // stance as at the start (the trial's clock stands still meanwhile).
  const auto restartAt = [&](double x, double y) {
    const engine::Pose p = w.torsoPose(0);
    w.placeRobot(0, x, y, headingOf(p));
    engine = agents::WalkEngine(model, c.walk);
    settleIntoStance(t, engine, targets);
    t.driver.setControl(walkControl);
  };
  // Followed period by period, so that more than half a turn is told apart.
  double heading = headingOf(start);
  for (i = 0; i < periods; ++i) {
    t.period();
    const double yaw = headingOf(w.torsoPose(0));
    r.turned += std::remainder(yaw - heading, 2 * M_PI);
    heading = yaw;
    if (!w.isStanding(0)) {
      r.fell = true;
      r.fell_at = static_cast<double>(i) * dt;
      if (!falls) break;
      // Counting falls: put the robot back up where it fell and walk on.
      ++*falls;
      if (c.verbose) {
        const Eigen::Vector3d now = schedule(r.fell_at),
                              before = schedule(std::max(0.0, r.fell_at - 2.0));
        std::fprintf(stderr, "fall at %.2f s, command %.2f %.2f %.2f (before: %.2f %.2f %.2f)\n",
                     r.fell_at, now.x(), now.y(), now.z(), before.x(), before.y(), before.z());
      }
      const Vec3 p = w.torsoPose(0).translation();
      restartAt(p.x(), p.y());
      continue;
    }
    if (falls) {
      // Random walking: near the field's lines the robot is put back in the middle (facing as
      // it was; not a fall), so that it never walks into a goal or off the carpet: what this
      // trial counts is the walk's own falls.
      const Vec3 p = w.torsoPose(0).translation();
      const double margin = 1.0;  // m, inside the lines
      if (std::abs(p.x()) > w.field().halfLength() - margin ||
          std::abs(p.y()) > w.field().halfWidth() - margin) {
        if (c.verbose)
          std::fprintf(stderr, "back to the middle at %.2f s from %.2f %.2f\n",
                       static_cast<double>(i) * dt, p.x(), p.y());
        restartAt(0.0, 0.0);
        continue;
      }
    }
    if (c.verbose && i % 5 == 0) {  // a trace every 0.05 s, for tuning
      const engine::Pose torso = w.torsoPose(0);
      const Vec3 p = torso.translation();
      const auto& f = w.sensorFrame(0);
      const auto& kin = engine.kinematics();
      std::fprintf(stderr,
                   "t %.2f torso %.3f %.3f %.3f roll %+.3f pitch %+.3f turned %+.3f odometry %.3f "
                   "phase %.2f "
                   "support %s  feet z %.3f / %.3f\n",
                   static_cast<double>(i) * dt, p.x(), p.y(), p.z(), f.angles[0], f.angles[1],
                   r.turned, engine.odometry().x, engine.phase(),
                   engine.supportLeg() == agents::Leg::Left ? "L" : "R",
                   w.linkPose(0, kin.footLink(agents::Leg::Left)).translation().z(),
                   w.linkPose(0, kin.footLink(agents::Leg::Right)).translation().z());
    }
  }
  const engine::Pose end = w.torsoPose(0);
  const Vec3 d = start.linear().transpose() * (end.translation() - start.translation());
  r.distance = std::hypot(d.x(), d.y());
  r.speed = (vx != 0 || vy == 0 ? d.x() : d.y()) / seconds;
  r.lateral = vx != 0 || vy == 0 ? d.y() : d.x();
  return r;
}

int randomCommandsTrial(const TrialContext& c, uint64_t seed, double seconds, double hold,
                        double stand_share) {
  // A new command every `hold` s in the bench file's ranges (a Nao: forward -0.1..0.3 m/s,
  // sideways -0.1..0.1 m/s, turn -0.8..0.8 rad/s), each part with a 1 in 4 chance of 0.
  const MotionBench& b = c.bench;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  const auto pick = [&](const std::array<double, 2>& range) {
    return u(rng) < 0.25 ? 0.0 : range[0] + (range[1] - range[0]) * u(rng);
  };
  std::vector<Eigen::Vector3d> commands;
  std::vector<bool> stand;
  for (int i = 0; i < static_cast<int>(seconds / hold) + 1; ++i) {
    commands.emplace_back(pick(b.random_forward), pick(b.random_sideways), pick(b.random_turn));
    // Drawn only when asked for: random_commands keeps the sequence it always had.
    stand.push_back(stand_share > 0.0 && u(rng) < stand_share);
  }
  const auto at = [&](double t) { return static_cast<size_t>(t / hold); };
  int falls = 0;
  walkTrial(
      c, [&](double t) { return commands[at(t)]; }, seconds, &falls,
      [&](double t) { return static_cast<bool>(stand[at(t)]); });
  return falls;
}

}  // namespace simsoccer::apps::motion
