// The ball on the carpet and against the goal (real Bullet).
#include <gtest/gtest.h>

#include <cmath>

#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using engine::Vec3;

namespace {

world::Scenario emptyField() {
  world::Scenario s = test::scenario(0);
  s.ball_position = {-3.0, 0.0, -1.0};
  return s;
}

// Rolls the ball from rest at `speed` along `heading` (rad from +x; rolling, not sliding) and
// returns where it stops, from where it started.
Vec3 rollTravel(double speed, double heading) {
  world::World w(emptyField());
  auto b = w.ballState();
  const double r = w.field().ball.radius;
  b.linear_velocity = speed * Vec3(std::cos(heading), std::sin(heading), 0);
  b.angular_velocity = Vec3::UnitZ().cross(b.linear_velocity) / r;
  w.setBallState(b);
  const Vec3 start = b.pose.translation();
  for (int i = 0; i < 4000; ++i) {
    w.step();
    if (w.ballState().linear_velocity.norm() < 0.005) break;
  }
  return w.ballState().pose.translation() - start;
}

double rollDistance(double speed) {
  return rollTravel(speed, 0.0).x();
}

}  // namespace

TEST(Ball, RollingDistanceInBand) {
  const double d = rollDistance(2.0);
  std::printf("ball rolled at 2 m/s stops after %.2f m\n", d);
  EXPECT_GE(d, 3.0);
  EXPECT_LE(d, 6.0);
  EXPECT_LT(rollDistance(1.0), d);  // slower ball, shorter roll
}

// The carpet's rolling resistance is the same whichever way the ball rolls: a ball rolled at an
// angle to the field's axes keeps its direction and goes as far as one rolled along them.
// (Bullet limits it about two fixed axes of the contact plane, each on its own: a ball rolled
// at 2 m/s, 8.5 deg off the x axis, ran on along the axis 0.1 m off it.)
TEST(Ball, RollsStraightAndAsFarWhateverItsDirection) {
  const double along = rollTravel(2.0, 0.0).norm();
  for (const double heading : {0.15, M_PI / 4, -0.5}) {  // from (-3, 0), on the field
    const Vec3 d = rollTravel(2.0, heading);
    std::printf("ball rolled at 2 m/s, %.2f rad: stops after %.3f m at %.4f rad\n", heading,
                d.norm(), std::atan2(d.y(), d.x()));
    EXPECT_NEAR(std::atan2(d.y(), d.x()), heading, 0.01);
    EXPECT_NEAR(d.norm(), along, 0.02 * along);
  }
}

TEST(Ball, RestsOnTheCarpet) {
  world::World w(emptyField());
  for (int i = 0; i < 400; ++i) w.step();
  const auto b = w.ballState();
  EXPECT_NEAR(b.pose.translation().z(), w.field().ball.radius, 0.002);
  EXPECT_LT(b.linear_velocity.norm(), 1e-3);
}

TEST(Ball, BouncesOffGoalPost) {
  world::Scenario s = emptyField();
  const double post_x = 4.5, post_y = 0.8;  // left post of the +x goal (field frame)
  s.ball_position = {post_x - 1.0, post_y, -1.0};
  world::World w(s);
  auto b = w.ballState();
  b.linear_velocity = Vec3(3.0, 0, 0);
  b.angular_velocity = Vec3(0, 3.0 / w.field().ball.radius, 0);
  w.setBallState(b);
  double min_gap = 1e9;
  const double dt = w.scenario().physics.dt;
  for (int i = 0; i < static_cast<int>(std::lround(1.0 / dt)); ++i) {  // 1 s
    w.step();
    const Vec3 p = w.ballState().pose.translation();
    min_gap = std::min(min_gap, std::hypot(p.x() - post_x, p.y() - post_y));
  }
  const auto end = w.ballState();
  std::printf("ball after hitting the post: x %.3f, vx %.3f, closest centre distance %.3f\n",
              end.pose.translation().x(), end.linear_velocity.x(), min_gap);
  EXPECT_LT(end.linear_velocity.x(), -0.2);             // came back
  EXPECT_LT(end.pose.translation().x(), post_x - 0.1);  // in front of the post
  // Never passed through it: at most one step's travel into it (3 m/s: 30 mm
  // in a 10 ms step, 15 mm in 5 ms), and 5 mm more.
  EXPECT_GT(min_gap, w.field().ball.radius + 0.05 - (3.0 * dt + 0.005));
}

// A soft ball bounces off a robot at its own restitution (the larger of the
// two materials' counts; the robot's is 0), as it does off a post: rolled at
// a standing robot's foot at 2 m/s, it comes back. With Bullet's product rule
// (0.5 x 0) it came back at 0.3 m/s, what the foot gave way. (Still spinning forwards, it
// loses its speed back on the carpet within a few tenths of a second.)
TEST(Ball, BouncesOffARobotsFoot) {
  world::Scenario s = test::scenario(1);
  world::World w(s);
  const auto& model = *w.robot(0).model;
  const auto& stand = model.pose("stand");
  std::vector<double> pos(model.actuators.size(), 0.0), stiff(pos.size(), 1.0);
  for (size_t a = 0; a < pos.size(); ++a)
    if (model.actuators[a].kind == robots::Actuator::Kind::Joint)
      pos[a] = stand[static_cast<size_t>(model.actuators[a].index)];
  w.setCommand(0, pos, stiff);
  for (int i = 0; i < 200; ++i) w.step();  // 1 s in the stand pose
  ASSERT_TRUE(w.isStanding(0));
  const Vec3 foot = w.linkPose(0, model.body->linkIndex("RFoot")).translation();
  const double r = w.field().ball.radius;
  engine::RigidBodyState b;
  b.pose.translation() = Vec3(foot.x() + 0.4, foot.y(), r);
  b.linear_velocity = Vec3(-2.0, 0, 0);
  b.angular_velocity = Vec3(0, -2.0 / r, 0);
  w.setBallState(b);
  double back = 0.0;               // the fastest the ball goes away from the robot
  for (int i = 0; i < 100; ++i) {  // 0.5 s: it meets the toe after about 0.12 s
    w.step();
    back = std::max(back, w.ballState().linear_velocity.x());
  }
  std::printf("ball back from the foot at up to %.2f m/s\n", back);
  EXPECT_GT(back, 0.6);  // half of 2 m/s, less what the foot gives way
  EXPECT_GT(w.ballState().pose.translation().x(), foot.x() + 0.15);
  EXPECT_TRUE(w.isStanding(0));
}

// The ball dropped on the carpet bounces at its own restitution (0.5: the
// larger of the two materials' counts): from 0.5 m it comes back up 0.17 m
// (with Bullet's product rule, 0.5 x 0, it would not bounce).
TEST(Ball, BouncesOnTheCarpet) {
  world::World w(emptyField());
  const double r = w.field().ball.radius, drop = 0.5;
  engine::RigidBodyState b;
  b.pose.translation() = Vec3(-3.0, 0.0, r + drop);
  w.setBallState(b);
  double lowest = 1e9, rebound = 0.0;
  bool fell = false;
  for (int i = 0; i < 400; ++i) {  // 2 s
    w.step();
    const double z = w.ballState().pose.translation().z() - r;
    if (!fell) {
      lowest = std::min(lowest, z);
      fell = w.ballState().linear_velocity.z() > 0.0 && lowest < 0.01;
    } else {
      rebound = std::max(rebound, z);
    }
  }
  std::printf("ball dropped from %.2f m comes back up %.3f m\n", drop, rebound);
  EXPECT_GT(rebound, 0.06);
  EXPECT_LT(rebound, 0.2);
}

// The field's estimate of how far a rolled ball goes (the match records judge by it whether a
// shot was going in when a defender touched it) against the real roll: within 5 %.
TEST(Ball, TheFieldsRollingEstimateMatchesTheRealRoll) {
  const world::World w(emptyField());
  const fields::FieldModel& f = w.field();
  for (const double speed : {1.0, 2.0, 3.0}) {
    const double estimate = f.ballRollingDistance(speed);
    const double real = rollDistance(speed);
    std::printf("ball rolled at %.0f m/s: stops after %.2f m, estimated %.2f m\n", speed, real,
                estimate);
    EXPECT_NEAR(estimate, real, 0.05 * real);
  }
  // At the goal at +x from 2 m out: in at 2 m/s (rolls about 4.5 m), short at 1 m/s; wide of
  // the posts, away from the goal, or at rest, no goal; the other way, the goal at -x.
  const double x = f.halfLength() - 2.0;
  EXPECT_EQ(f.goalReachedByRollingBall(x, 0.0, 2.0, 0.0), 1);
  EXPECT_EQ(f.goalReachedByRollingBall(x, 0.0, 1.0, 0.0), 0);
  EXPECT_EQ(f.goalReachedByRollingBall(x, 0.0, 2.0, 0.8), 0);  // crosses the line 0.83 m aside
  EXPECT_EQ(f.goalReachedByRollingBall(x, 0.0, 2.0, 0.6), 1);  // 0.62 m aside: inside the posts
  EXPECT_EQ(f.goalReachedByRollingBall(x, 0.0, -2.0, 0.0), 0);
  EXPECT_EQ(f.goalReachedByRollingBall(x, 0.0, 0.0, 0.0), 0);
  EXPECT_EQ(f.goalReachedByRollingBall(-x, 0.2, -2.0, 0.0), -1);
}
