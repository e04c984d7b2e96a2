// Kicking: one kick from the walk's stance with the ball in front of the
// kicking foot; the ball's travel after 6 s.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "trial.hpp"

namespace simsoccer::apps::motion {
namespace {

// For tuning a kick: while the kicking foot is near the ball, its speed along
// the kick (from `last_foot`, a control period ago), its height and its
// sole's lowest corner, and the ball's speed and spin; `start`: the ball's
// start.
void traceKick(const world::World& w, int foot_link, const Vec3& start, double dt, double t,
               Vec3& last_foot) {
  const auto foot_pose = w.linkPose(0, foot_link);
  const Vec3 foot = foot_pose.translation();
  const engine::RigidBodyState ball = w.ballState();
  if ((foot - ball.pose.translation()).norm() < 0.4 && t < 3.5) {
    double sole = 1e9;  // the bottom corners of the foot's collision box
    const auto& model = *w.robot(0).model;
    const engine::Shape& box = model.body->links[static_cast<size_t>(foot_link)].shapes.front();
    for (double cx : {-0.5, 0.5})
      for (double cy : {-0.5, 0.5})
        sole = std::min(sole,
                        (foot_pose * box.pose *
                         Vec3(cx * box.extents.x(), cy * box.extents.y(), -0.5 * box.extents.z()))
                            .z());
    std::fprintf(stderr,
                 "t %.2f foot x %+.3f z %.3f sole %.3f speed %+.2f m/s | ball x %+.3f speed %.2f "
                 "m/s spin %+.1f rad/s (rolling %+.1f)\n",
                 t, foot.x() - start.x(), foot.z(), sole, (foot.x() - last_foot.x()) / dt,
                 ball.pose.translation().x() - start.x(), ball.linear_velocity.norm(),
                 ball.angular_velocity.y(), ball.linear_velocity.x() / w.field().ball.radius);
  }
  last_foot = foot;
}

// How far the foot's collision shapes reach ahead of its frame (m).
double toe(const robots::RobotModel& model, int foot_link) {
  double x = 0.0;
  for (const engine::Shape& s : model.body->links[static_cast<size_t>(foot_link)].shapes)
    if (s.type == engine::ShapeType::Box)
      x = std::max(x, s.pose.translation().x() + 0.5 * s.extents.x());
  return x;
}

}  // namespace

KickResult kickTrial(const TrialContext& c, agents::Leg foot, double ball_offset, uint64_t seed,
                     double gap, int steps_first) {
  world::Scenario s = emptyField(c);
  s.seed = seed;
  TrialWorld t(s, c);
  world::World& w = t.world;
  const auto& model = *w.robot(0).model;
  agents::WalkEngine walk(model, c.walk);
  agents::KickEngine engine(model, c.walk, c.kick);
  std::vector<double> targets = model.pose("stand");
  settleIntoStance(t, walk, targets);
  if (steps_first > 0) {
    // Stepping on the spot, then stopping: the kick starts from the sway the last steps leave.
    const double dt = t.dt();
    walk.setVelocity(0.0, 0.0, 0.0);
    t.driver.setControl([&](const world::World& world, std::span<float> p, std::span<float> k) {
      walkPeriod(world, walk, dt, targets, p, k);
      return true;
    });
    const int periods = static_cast<int>(std::lround(steps_first * c.walk.step_period / dt));
    for (int i = 0; i < periods; ++i) t.period();
    walk.stop(/*settle=*/true);  // as the motion controller stops before a kick
    for (int i = 0; i < static_cast<int>(std::lround(3.0 / dt)) && walk.walking(); ++i) t.period();
    // Then standing for the kick's ready_time, as the motion controller does.
    for (int i = 0; i < static_cast<int>(std::lround(c.kick.ready_time / dt)); ++i) t.period();
    t.driver.setControl({});
  }
  // In front of where the kicking foot swings: beside the support foot, in the gait's stance.
  const int foot_link = engine.kinematics().footLink(foot);
  const agents::Leg support = foot == agents::Leg::Left ? agents::Leg::Right : agents::Leg::Left;
  const Vec3 f = w.linkPose(0, engine.kinematics().footLink(support)) *
                 Vec3(0.0, (foot == agents::Leg::Left ? 1.0 : -1.0) * c.walk.step_width, 0.0);
  engine::RigidBodyState b;
  b.pose.translation() = Vec3(f.x() + toe(model, foot_link) + w.field().ball.radius + gap,
                              f.y() + ball_offset, w.field().ball.radius);
  w.setBallState(b);
  const Vec3 start = b.pose.translation();
  std::vector<double> measured;
  agents::measuredJointAngles(model, w.sensorFrame(0).position, measured);
  engine.start(foot, measured);
  KickResult r;
  const double dt = t.dt();
  t.driver.setControl([&](const world::World& world, std::span<float> p, std::span<float> k) {
    if (!engine.active()) return false;  // the last targets hold
    const auto& fr = world.sensorFrame(0);
    engine.update(dt, Vec3(fr.gyroscope[0], fr.gyroscope[1], fr.gyroscope[2]), targets,
                  {fr.angles[0], fr.angles[1]});
    bodyTargetsToCommand(model, targets, 1.0, p, k);
    return true;
  });
  Vec3 last_foot = w.linkPose(0, foot_link).translation();  // for the trace
  for (int i = 0; i < static_cast<int>(std::lround(6.0 / dt)); ++i) {
    t.period();
    r.fell = r.fell || !w.isStanding(0);
    if (c.verbose) traceKick(w, foot_link, start, dt, (i + 1) * dt, last_foot);
  }
  const Vec3 d = w.ballState().pose.translation() - start;
  r.distance = std::hypot(d.x(), d.y());
  r.direction = std::atan2(d.y(), d.x());
  return r;
}

}  // namespace simsoccer::apps::motion
