// The engine's articulation solver (engine/src/articulation_solver: contact
// rows from each link's spatial basis and the factorised inertia, its own
// iteration loop) against Bullet's own rows and iterations: the same physics
// up to rounding, with the engine's rows actually built (feet on the carpet,
// arms against arms, a robot lying on the carpet).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "simsoccer/world/world.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

struct Outcome {
  std::vector<engine::Vec3> torsos;  // m, per robot
  std::vector<double> joints;        // rad, every robot's
  engine::Vec3 ball;                 // m
  long most_basis_rows = 0;          // in any step
  long solved_rows = 0;              // articulation contact rows solved one by one, all steps
  long between_articulations = 0;    // contact rows between two robots, all steps
  double inertia_mismatch = -1;      // factorised M^-1 against Bullet's pass, relative
  int standing = 0;
};

// Two robots side by side for 1 s, the ball rolling into the first one's
// feet: arms swinging, the legs in a squat that keeps the feet flat (knee +a,
// hip and ankle pitch -a/2 each), so the feet carry load and friction. With
// `touching`, the two stand 0.3 m apart so that their arms hit each other,
// and a third lies on its back beside them (torso, arms and legs on the
// carpet at one or two points each).
Outcome run(const std::filesystem::path& robot, bool own, int friction_directions = 2,
            bool touching = false) {
  world::Scenario s = test::scenario(touching ? 3 : 2, 3);
  s.robot_model_file = robot;
  s.physics.bullet_solver = !own;
  s.physics.envelope_in_solver = false;  // the bounds Bullet's solver can apply
  s.physics.contact_warm_start = 0.0;    // Bullet's contact rows start from zero
  s.physics.friction_directions = friction_directions;
  if (touching) {
    s.robots[1].x = s.robots[0].x;
    s.robots[1].y = s.robots[0].y + 0.3;
    s.robots[1].yaw = s.robots[0].yaw;
  }
  world::World w(s);
  w.physics().checkInverseInertia(true);
  if (touching) {
    const engine::Vec3 torso = w.torsoPose(0).translation();
    engine::Pose lying = engine::Pose::Identity();
    lying.linear() = engine::Quat(Eigen::AngleAxisd(-0.5 * M_PI, engine::Vec3::UnitY()))
                         .toRotationMatrix();  // face up
    lying.translation() = engine::Vec3(torso.x(), torso.y() - 0.6, 0.12);
    w.placeRobot(2, lying, "stand");
  }
  {
    // The ball rolls into the first robot's feet: a rigid body's rows among
    // the articulations' (Bullet's conversion, the engine's iterations).
    const engine::Vec3 torso = w.torsoPose(0).translation();
    engine::RigidBodyState b;
    b.pose.translation() = engine::Vec3(torso.x() + 0.4, torso.y(), w.field().ball.radius);
    b.linear_velocity = engine::Vec3(-1.0, 0.0, 0.0);
    w.setBallState(b);
  }
  Outcome o;
  for (int i = 0; i < 200; ++i) {
    if (i % w.stepsPerControlPeriod() == 0)
      for (world::RobotId r = 0; r < w.robotCount(); ++r) {
        const auto& model = *w.robot(r).model;
        const auto& stand = model.pose("stand");
        const double squat = 0.15 * std::sin(5.0 * w.time() + r);
        for (size_t j = 0; j < model.body->joints.size(); ++j) {
          const std::string& name = model.body->joints[j].name;
          if (model.body->joints[j].mimic_of >= 0) continue;
          double target = stand[j];
          if (name.find("Knee") != std::string::npos)
            target += squat;
          else if (name.find("HipPitch") != std::string::npos ||
                   name.find("AnklePitch") != std::string::npos)
            target -= 0.5 * squat;
          else if (name.find("Hip") == std::string::npos && name.find("Ankle") == std::string::npos)
            target += 0.3 * std::sin(4.0 * w.time() + 0.5 * r + 0.3 * j);
          w.setJointTarget(r, static_cast<int>(j), target, 1.0);
        }
      }
    w.step();
    const engine::PhysicsWorld::ContactRowCounts rows = w.physics().lastStepContactRows();
    o.most_basis_rows = std::max(o.most_basis_rows, rows.basis);
    o.solved_rows += rows.solved;
    o.between_articulations += rows.between_articulations;
  }
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    o.torsos.push_back(w.torsoPose(r).translation());
    for (int j = 0; j < static_cast<int>(w.robot(r).model->body->joints.size()); ++j)
      o.joints.push_back(w.jointPosition(r, j));
    o.standing += w.isStanding(r) ? 1 : 0;
  }
  o.ball = w.ballState().pose.translation();
  o.inertia_mismatch = w.physics().inverseInertiaMismatch();
  return o;
}

// The largest gaps between the two solvers' outcomes, torsos and ball (m) and
// joints (rad), under their limits.
void compare(const char* what, const Outcome& own, const Outcome& bullet, double limit,
             double joint_limit) {
  double torso = 0.0, joint = 0.0;
  for (size_t r = 0; r < own.torsos.size(); ++r)
    torso = std::max(torso, (own.torsos[r] - bullet.torsos[r]).norm());
  for (size_t j = 0; j < own.joints.size(); ++j)
    joint = std::max(joint, std::abs(own.joints[j] - bullet.joints[j]));
  const double ball = (own.ball - bullet.ball).norm();
  std::printf(
      "%s after 1 s: torsos %.3g m, joints %.3g rad, ball %.3g m apart; up to %ld basis "
      "rows a step; factorised inertia and basis Jacobians within %.3g of Bullet's\n",
      what, torso, joint, ball, own.most_basis_rows, own.inertia_mismatch);
  std::printf("%s: in 1 s %ld contact rows solved one by one, %ld between two robots\n", what,
              own.solved_rows, own.between_articulations);
  // Every step's factorisation of each robot, column by column (also the
  // implicit servo rows' columns, solved six at a time), and every link's
  // basis Jacobians and their responses: the same up to the rounding
  // of Bullet's single-precision pass (its own inverse is symmetric to about
  // 1e-7 of its largest entry; the basis responses agree to about 1.4e-4 of
  // their largest entry, the columns of M^-1 to 2e-5); a wrong axis, pivot,
  // lever arm, mass or inertia is off by percent (a flipped lever arm: 0.7).
  EXPECT_GE(own.inertia_mismatch, 0.0) << what << ": nothing checked";
  EXPECT_LT(own.inertia_mismatch, 1e-3) << what;
  EXPECT_LT(bullet.inertia_mismatch, 0.0) << what << ": Bullet's rows factorise nothing";
  EXPECT_EQ(bullet.solved_rows, 0) << what;
  EXPECT_EQ(bullet.between_articulations, 0) << what;
  EXPECT_EQ(own.standing, 2) << what;
  EXPECT_EQ(bullet.standing, 2) << what;
  // A wrong sign, lever arm, bound or bias moves a robot by millimetres.
  EXPECT_LT(torso, limit) << what;
  EXPECT_LT(joint, joint_limit) << what;
  EXPECT_LT(ball, limit) << what;
}

}  // namespace

TEST(ArticulationSolver, MatchesBulletsOwnRowsAndIterationsUpToRounding) {
  const Outcome own = run(test::naoH25(), true), bullet = run(test::naoH25(), false);
  compare("Nao", own, bullet, 2e-5, 2e-4);
  // Both feet flat, four points each, a normal and two friction rows a
  // point, both robots: the feet's rows come from the basis.
  EXPECT_EQ(own.most_basis_rows, 2 * 2 * 4 * 3);
  EXPECT_EQ(bullet.most_basis_rows, 0);
}

TEST(ArticulationSolver, MatchesBulletWithOneFrictionRowAndForTheBoosterK1) {
  // With one friction row the feet slip along the free tangent, which makes
  // the squat sensitive to the last bits: looser limits (a wrong row still
  // moves a robot by millimetres).
  const Outcome own = run(test::naoH25(), true, 1), bullet = run(test::naoH25(), false, 1);
  compare("Nao, one friction row", own, bullet, 1e-3, 1e-2);
  EXPECT_EQ(own.most_basis_rows, 2 * 2 * 4 * 2);
  const auto k1 = test::sourceDir() / "robots" / "booster_k1.yaml";
  const Outcome own_k1 = run(k1, true), bullet_k1 = run(k1, false);
  compare("Booster K1", own_k1, bullet_k1, 2e-5, 2e-4);
  EXPECT_GT(own_k1.most_basis_rows, 0);
}

TEST(ArticulationSolver, MatchesBulletWithRobotsTouchingAndOneLying) {
  // Arms against arms (both sides articulations) and a lying robot's links
  // on the carpet at one or two points: rows the engine builds from the
  // factorisation and solves one by one.
  const Outcome own = run(test::naoH25(), true, 2, true);
  const Outcome bullet = run(test::naoH25(), false, 2, true);
  compare("Nao, touching and lying", own, bullet, 2e-5, 2e-4);
  EXPECT_GT(own.solved_rows, 1000);
  EXPECT_GT(own.between_articulations, 100);
}
