// The walk engine's own geometry, without physics: foot lift, step lengths,
// odometry, stopping. (Walking on the physics: bench motion and the DDS test.)
#include <gtest/gtest.h>

#include "simsoccer/agents/motion/walk_engine.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using agents::Leg;

namespace {

struct Feet {
  agents::Pose left, right;
};

Feet feetOf(const agents::WalkEngine& e, const std::vector<double>& q) {
  agents::LegAngles l, r;
  for (int i = 0; i < 6; ++i) {
    l[i] = q[static_cast<size_t>(e.kinematics().joints(Leg::Left)[i])];
    r[i] = q[static_cast<size_t>(e.kinematics().joints(Leg::Right)[i])];
  }
  return {e.kinematics().forward(Leg::Left, l), e.kinematics().forward(Leg::Right, r)};
}

}  // namespace

TEST(WalkEngine, SwingFootLiftsAndLandsAtItsPlacement) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkParameters p;
  p.hip_roll_compensation =
      0.0;  // pure geometry: the sag compensation bends the support leg on purpose
  agents::WalkEngine e(model, p);
  std::vector<double> q = model.pose("stand");
  e.update(0.01, engine::Vec3::Zero(), 0.0, q);
  const Feet standing = feetOf(e, q);
  EXPECT_NEAR(standing.left.translation().z(), -p.ankle_height, 1e-6);
  EXPECT_NEAR(standing.left.translation().y() - standing.right.translation().y(), p.step_width,
              1e-6);
  e.setVelocity(0.2, 0.0, 0.0);
  double apex = -1.0;
  for (int i = 0; i < 25; ++i) {  // the first step: the left foot swings
    e.update(0.01, engine::Vec3::Zero(), 0.0, q);
    const Feet f = feetOf(e, q);
    apex = std::max(apex, f.left.translation().z() - f.right.translation().z());
    EXPECT_NEAR(f.right.translation().z(), -p.ankle_height, 1e-6);  // the support foot stays down
  }
  EXPECT_NEAR(apex, p.foot_lift, 0.0005);
}

TEST(WalkEngine, OdometryFollowsTheCommandAndStopEndsWithFeetTogether) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  agents::WalkEngine e(model);
  std::vector<double> q = model.pose("stand");
  e.setVelocity(0.2, 0.0, 0.0);
  for (int i = 0; i < 400; ++i) e.update(0.01, engine::Vec3::Zero(), 0.0, q);  // 4 s
  // Ramped up by 0.02 m per step to 0.05 m per step (0.2 m/s at 4 steps/s).
  EXPECT_GT(e.odometry().x, 0.7);
  EXPECT_LT(e.odometry().x, 0.85);
  EXPECT_NEAR(e.odometry().y, 0.0, 1e-9);
  e.stop();
  for (int i = 0; i < 300 && e.walking(); ++i) e.update(0.01, engine::Vec3::Zero(), 0.0, q);
  EXPECT_FALSE(e.walking());
  const Feet f = feetOf(e, q);
  EXPECT_NEAR(f.left.translation().x(), f.right.translation().x(), 1e-3);  // side by side
  EXPECT_NEAR(f.left.translation().z(), f.right.translation().z(), 1e-6);
  // A command beyond the limits is scaled into them.
  agents::WalkEngine fast(model);
  fast.setVelocity(5.0, 0.0, 0.0);
  for (int i = 0; i < 1000; ++i) fast.update(0.01, engine::Vec3::Zero(), 0.0, q);
  EXPECT_NEAR(fast.odometry().x / 10.0, fast.parameters().max_forward / 0.25, 0.03);
}
