// The rows of a foot's contact with the carpet built from the link's spatial
// basis (engine/src/link_contact_solver) against Bullet's own rows: the same
// physics up to rounding, with the basis actually building the feet's rows.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

struct Outcome {
  engine::Vec3 torso;          // m
  std::vector<double> joints;  // rad
  long basis_rows = 0;         // in the last step
  int standing = 0;
};

// Two Naos standing for `steps` steps (5 ms), head and arms on sinusoids
// around the stand pose, the legs still (feet flat: four points each).
Outcome run(bool own, int steps) {
  world::Scenario s = test::scenario(2, 3);
  s.physics.bullet_solver = !own;
  world::World w(s);
  for (int i = 0; i < steps; ++i) {
    if (i % w.stepsPerControlPeriod() == 0)
      for (world::RobotId r = 0; r < w.robotCount(); ++r) {
        const auto& model = *w.robot(r).model;
        const auto& stand = model.pose("stand");
        for (size_t j = 0; j < model.body->joints.size(); ++j) {
          const std::string& name = model.body->joints[j].name;
          if (model.body->joints[j].mimic_of >= 0) continue;
          const bool leg = name.find("Hip") != std::string::npos ||
                           name.find("Knee") != std::string::npos ||
                           name.find("Ankle") != std::string::npos;
          w.setJointTarget(
              r, static_cast<int>(j),
              stand[j] + (leg ? 0.0 : 0.3 * std::sin(4.0 * w.time() + 0.5 * r + 0.3 * j)), 1.0);
        }
      }
    w.step();
  }
  Outcome o;
  o.torso = w.torsoPose(0).translation();
  for (int j = 0; j < static_cast<int>(w.robot(0).model->body->joints.size()); ++j)
    o.joints.push_back(w.jointPosition(0, j));
  o.basis_rows = w.physics().lastStepBasisRows();
  for (world::RobotId r = 0; r < w.robotCount(); ++r) o.standing += w.isStanding(r) ? 1 : 0;
  return o;
}

}  // namespace

TEST(ArticulationSolver, MatchesBulletsOwnRowsAndIterationsUpToRounding) {
  const int steps = 200;  // 1 s
  const Outcome bullet = run(false, steps), basis = run(true, steps);
  double joint_gap = 0.0;
  for (size_t j = 0; j < basis.joints.size(); ++j)
    joint_gap = std::max(joint_gap, std::abs(basis.joints[j] - bullet.joints[j]));
  const double torso_gap = (basis.torso - bullet.torso).norm();
  std::printf("after 1 s: torso %.3g m, joints %.3g rad apart; basis rows %ld, Bullet's path %ld\n",
              torso_gap, joint_gap, basis.basis_rows, bullet.basis_rows);
  EXPECT_EQ(bullet.basis_rows, 0);
  // Both feet flat on the carpet, four points each, a normal and two
  // friction rows per point, both robots.
  EXPECT_EQ(basis.basis_rows, 2 * 2 * 4 * 3);
  EXPECT_EQ(basis.standing, 2);
  EXPECT_EQ(bullet.standing, 2);
  // A wrong sign, lever arm or bias would move the robot by millimetres.
  EXPECT_LT(torso_gap, 1e-4);
  EXPECT_LT(joint_gap, 1e-3);
}
