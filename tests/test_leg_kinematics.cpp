// Leg kinematics on the robot models' own data: forward kinematics against
// the model's frames, inverse kinematics round trips, limits, the Nao's shared
// HipYawPitch, the Booster K1's independent legs in another joint order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <tuple>

#include "simsoccer/agents/motion/leg_kinematics.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using agents::Leg;
using agents::LegAngles;
using engine::Vec3;

namespace {

LegAngles randomLeg(const agents::LegKinematics& k, Leg leg, std::mt19937_64& rng) {
  LegAngles q;
  for (int i = 0; i < 6; ++i) {
    // Inside the limits, knee bent (a standing or walking leg, not a folded one).
    double lo = k.lower(leg, i), hi = k.upper(leg, i);
    if (i == k.index(agents::LegJoint::Knee)) lo = std::max(lo, 0.2);
    if (i == k.index(agents::LegJoint::HipYaw)) lo = std::max(lo, -0.6), hi = std::min(hi, 0.2);
    // The K1's hip pitch reaches -3 rad (the thigh folded up to the chest): a walking leg's
    // range instead (the Nao's, -1.54 at most, is sampled whole).
    if (i == k.index(agents::LegJoint::HipPitch) && lo < -2.0) lo = -1.2, hi = std::min(hi, 0.5);
    q[i] = std::uniform_real_distribution<double>(lo + 0.02, hi - 0.02)(rng);
  }
  return q;
}

}  // namespace

TEST(LegKinematics, ForwardMatchesTheModelFrames) {
  const robots::RobotModel model = robots::loadRobotModel(test::naoH25());
  const agents::LegKinematics k(model);
  std::mt19937_64 rng(3);
  std::vector<double> q(model.body->joints.size(), 0.0);
  for (const Leg leg : {Leg::Left, Leg::Right}) {
    const LegAngles a = randomLeg(k, leg, rng);
    for (int i = 0; i < 6; ++i) q[static_cast<size_t>(k.joints(leg)[i])] = a[i];
    const auto frames = model.body->linkFramesAt(q);
    const int foot = model.body->joints[static_cast<size_t>(k.joints(leg)[5])].child_link;
    EXPECT_TRUE(k.forward(leg, a).isApprox(frames[static_cast<size_t>(foot)], 1e-12));
  }
  EXPECT_NEAR(k.soleDepth(), 0.04519, 0.0005);  // nao.md: foot height 45.19 mm
  EXPECT_NEAR(k.hip(Leg::Left).y(), 0.05, 1e-9);
}

TEST(LegKinematics, InverseOfForwardIsIdentityWithinATenthOfAMillimetre) {
  for (const auto& file : {test::naoH25(), test::naoH21()}) {
    const robots::RobotModel model = robots::loadRobotModel(file);
    const agents::LegKinematics k(model);
    std::mt19937_64 rng(11);
    double worst_position = 0, worst_orientation = 0;
    for (int trial = 0; trial < 500; ++trial) {
      LegAngles l = randomLeg(k, Leg::Left, rng), r = randomLeg(k, Leg::Right, rng);
      r[0] = l[0];  // one HipYawPitch motor
      const agents::Pose fl = k.forward(Leg::Left, l), fr = k.forward(Leg::Right, r);
      const agents::LegSolution s = k.inverse(fl, fr);
      for (const auto& [leg, q, target] :
           {std::tuple{Leg::Left, s.left, fl}, std::tuple{Leg::Right, s.right, fr}}) {
        const agents::Pose got = k.forward(leg, q);
        worst_position =
            std::max(worst_position, (got.translation() - target.translation()).norm());
        worst_orientation =
            std::max(worst_orientation,
                     Eigen::AngleAxisd(got.linear() * target.linear().transpose()).angle());
        for (int i = 0; i < 6; ++i) {
          EXPECT_GE(q[i], k.lower(leg, i) - 1e-12);
          EXPECT_LE(q[i], k.upper(leg, i) + 1e-12);
        }
      }
      EXPECT_EQ(s.left[0], s.right[0]);  // the shared hinge
    }
    std::printf(
        "%s: 500 random reachable foot pairs, worst position error %.2e m, orientation "
        "%.2e rad\n",
        model.name.c_str(), worst_position, worst_orientation);
    EXPECT_LT(worst_position, 1e-4);
    EXPECT_LT(worst_orientation, 1e-3);
  }
}

TEST(LegKinematics, UnreachableTargetsStayWithinLimits) {
  const agents::LegKinematics k(robots::loadRobotModel(test::naoH25()));
  agents::Pose far = agents::Pose::Identity();
  far.translation() = Vec3(0.0, 0.05, -0.5);  // below a straight leg
  const agents::LegSolution s = k.inverse(far, far);
  EXPECT_GT(s.position_error, 0.1);
  for (int i = 0; i < 6; ++i) {
    EXPECT_GE(s.left[i], k.lower(Leg::Left, i));
    EXPECT_LE(s.left[i], k.upper(Leg::Left, i));
  }
  EXPECT_NEAR(s.left[3], 0.0, 0.1);  // the knee as straight as it goes
}

TEST(LegKinematics, FromTheLastSolutionAsCloseAsFromScratchAlongAPathAndAfterAStall) {
  // A turning walk's feet: yaws apart (the Nao's one HipYawPitch cannot serve both), each
  // pose solved from the last solution, as the walk does, and from scratch (other knee
  // bends tried): the same errors. A last solution that stalled on an unreachable target
  // still tries other knee bends.
  for (const auto& file : {test::naoH25(), test::boosterK1()}) {
    const robots::RobotModel model = robots::loadRobotModel(file);
    const agents::LegKinematics k(model);
    agents::LegSolution last;
    bool have_last = false;
    double worst_gap = 0;
    for (int i = 0; i < 200; ++i) {
      const double phase = 0.05 * i;
      LegAngles l{}, r{};
      l[static_cast<size_t>(k.index(agents::LegJoint::Knee))] = 0.9 + 0.3 * std::sin(phase);
      l[static_cast<size_t>(k.index(agents::LegJoint::HipPitch))] = -0.45 - 0.1 * std::sin(phase);
      l[static_cast<size_t>(k.index(agents::LegJoint::AnklePitch))] = -0.45;
      r = l;
      r[static_cast<size_t>(k.index(agents::LegJoint::Knee))] = 0.9 - 0.3 * std::sin(phase);
      agents::Pose fl = k.forward(Leg::Left, l), fr = k.forward(Leg::Right, r);
      fr.rotate(Eigen::AngleAxisd(0.15 * std::cos(phase), Vec3::UnitZ()));  // turning
      const agents::LegSolution warm = k.inverse(fl, fr, have_last ? &last : nullptr);
      const agents::LegSolution cold = k.inverse(fl, fr);
      EXPECT_LT(warm.position_error, 1e-3);
      worst_gap = std::max({worst_gap, warm.position_error - cold.position_error,
                            warm.orientation_error - cold.orientation_error});
      last = warm;
      have_last = true;
    }
    std::printf("%s: from the last solution at most %.1e worse than from scratch\n",
                model.name.c_str(), worst_gap);
    EXPECT_LT(worst_gap, 1e-6);
    // Stalled: a target below a straight leg, then a reachable one from that solution.
    agents::Pose far = agents::Pose::Identity();
    far.translation() = Vec3(0.0, 0.05, -0.6);
    agents::Pose far_right = far;
    far_right.translation().y() = -0.05;
    const agents::LegSolution stalled = k.inverse(far, far_right);
    EXPECT_GT(stalled.position_error, 0.01);
    // From a bent solution the unreachable target stalls too: other knee bends are tried, and
    // the result is as close as from scratch.
    const agents::LegSolution from_bent = k.inverse(far, far_right, &last);
    EXPECT_NEAR(from_bent.position_error, stalled.position_error, 1e-6);
    LegAngles bent{};
    bent[static_cast<size_t>(k.index(agents::LegJoint::Knee))] = 1.2;
    bent[static_cast<size_t>(k.index(agents::LegJoint::HipPitch))] = -0.6;
    bent[static_cast<size_t>(k.index(agents::LegJoint::AnklePitch))] = -0.6;
    const agents::LegSolution back =
        k.inverse(k.forward(Leg::Left, bent), k.forward(Leg::Right, bent), &stalled);
    EXPECT_LT(back.position_error, 1e-4);
    EXPECT_LT(back.orientation_error, 1e-3);
  }
}

TEST(LegKinematics, TheBoosterK1sLegsInItsOwnJointOrderAndIndependent) {
  const robots::RobotModel model = robots::loadRobotModel(test::boosterK1());
  const agents::LegKinematics k(model);
  // The chain: hip pitch, roll, yaw, knee, ankle pitch, roll (the Nao: yaw-pitch, roll, pitch).
  using agents::LegJoint;
  EXPECT_EQ(k.index(LegJoint::HipPitch), 0);
  EXPECT_EQ(k.index(LegJoint::HipRoll), 1);
  EXPECT_EQ(k.index(LegJoint::HipYaw), 2);
  EXPECT_EQ(k.index(LegJoint::Knee), 3);
  EXPECT_EQ(k.index(LegJoint::AnklePitch), 4);
  EXPECT_EQ(k.index(LegJoint::AnkleRoll), 5);
  EXPECT_EQ(model.body->joints[static_cast<size_t>(k.joints(Leg::Left)[0])].name, "LeftHipPitch");
  EXPECT_EQ(model.body->joints[static_cast<size_t>(k.joints(Leg::Right)[2])].name, "RightHipYaw");
  EXPECT_EQ(k.footLink(Leg::Right), model.body->linkIndex("RightFoot"));
  EXPECT_NEAR(k.soleDepth(), 0.038, 1e-9);  // the foot box's face
  const agents::LegKinematics nao(robots::loadRobotModel(test::naoH25()));
  EXPECT_EQ(nao.index(LegJoint::HipYaw), 0);
  EXPECT_EQ(nao.index(LegJoint::HipPitch), 2);
  // Forward against the model's frames; inverse round trips with the two hip yaws apart (a
  // pair the Nao's one HipYawPitch motor could not reach).
  std::mt19937_64 rng(5);
  std::vector<double> q(model.body->joints.size(), 0.0);
  double worst_position = 0, worst_orientation = 0, yaws_apart = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const LegAngles l = randomLeg(k, Leg::Left, rng), r = randomLeg(k, Leg::Right, rng);
    for (int i = 0; i < 6; ++i) {
      q[static_cast<size_t>(k.joints(Leg::Left)[i])] = l[i];
      q[static_cast<size_t>(k.joints(Leg::Right)[i])] = r[i];
    }
    const auto frames = model.body->linkFramesAt(q);
    const agents::Pose fl = k.forward(Leg::Left, l), fr = k.forward(Leg::Right, r);
    EXPECT_TRUE(fl.isApprox(frames[static_cast<size_t>(k.footLink(Leg::Left))], 1e-12));
    EXPECT_TRUE(fr.isApprox(frames[static_cast<size_t>(k.footLink(Leg::Right))], 1e-12));
    const agents::LegSolution s = k.inverse(fl, fr);
    for (const auto& [leg, a, target] :
         {std::tuple{Leg::Left, s.left, fl}, std::tuple{Leg::Right, s.right, fr}}) {
      const agents::Pose got = k.forward(leg, a);
      worst_position = std::max(worst_position, (got.translation() - target.translation()).norm());
      worst_orientation = std::max(
          worst_orientation, Eigen::AngleAxisd(got.linear() * target.linear().transpose()).angle());
    }
    yaws_apart = std::max(yaws_apart, std::abs(s.left[2] - s.right[2]));
  }
  std::printf(
      "booster_k1: 300 random foot pairs, worst position error %.2e m, orientation %.2e rad\n",
      worst_position, worst_orientation);
  EXPECT_LT(worst_position, 1e-4);
  EXPECT_LT(worst_orientation, 1e-3);
  EXPECT_GT(yaws_apart, 0.3);
}
