// Forward and inverse kinematics of a robot's legs from the robot model's
// data: its `legs` (six hinges from the trunk down to each foot) with their
// origins, axes and limits, so the Nao H25 and H21 and the Booster K1 all work.
//
// Frames: the torso frame (x forward, y left, z up, origin at the torso
// joint frame); a foot's frame is its last joint's frame (the ankle roll, at
// the ankle, axes aligned with the torso at zero angles), the sole
// `soleDepth()` below.
//
// A leg joint's part (hip yaw, roll and pitch, knee, ankle pitch and roll)
// is read from its axis at zero angles, so the chain's order is the robot's
// own (the Nao: yaw-pitch, roll, pitch, ...; the K1: pitch, roll, yaw, ...).
// A right-leg joint that mimics the left one's (the Nao's two HipYawPitch
// hinges share one motor, nao.md 2.4) makes the legs dependent: inverse()
// solves both at once, one unknown per motor (11 on a Nao, 12 on a K1) for
// two foot poses (12 numbers), positions first, orientations as close as a
// shared hinge allows. Poses reachable with one shared angle (stepping
// straight, or any pair the robot can actually hold) are reached exactly.
#pragma once

#include <array>
#include <optional>
#include <vector>

#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::agents {

using engine::Pose;
using engine::Vec3;

enum class Leg { Left = 0, Right = 1 };

// One leg's six joint angles in its chain's order, trunk to foot (rad).
using LegAngles = std::array<double, 6>;

// A leg joint's part in walking. HipYaw: the hinge about the vertical (the
// Nao's HipYawPitch, at 45 degrees, counts as it).
enum class LegJoint { HipYaw, HipRoll, HipPitch, Knee, AnklePitch, AnkleRoll };

struct LegSolution {
  LegAngles left{}, right{};
  double position_error = 0.0;     // m, the larger of the two feet
  double orientation_error = 0.0;  // rad, the larger of the two feet
};

class LegKinematics {
 public:
  explicit LegKinematics(const robots::RobotModel& model);

  // The foot frame in the torso frame.
  Pose forward(Leg leg, const LegAngles& q) const;
  // Where one foot stands against the other, from body joint angles (body joint order, mimics
  // applied): `foot`'s frame in `other`'s as (x, y, yaw), when both soles are flat on one plane
  // (within 1 cm and 0.05 rad of each other: both on the ground); nothing otherwise.
  std::optional<Eigen::Vector3d> footAgainst(Leg foot, Leg other,
                                             const std::vector<double>& body_angles) const;
  // The midpoint of the feet's frames (the ankles) on the ground plane, in the frame the
  // perception reports in (below the torso's origin, x along its heading, y left; m), from body
  // joint angles and the IMU's roll and pitch (rad): where the ball lies against the feet,
  // whatever the torso's sway (a K1's torso swings 7 cm over its feet while it steps).
  Eigen::Vector2d feetCentre(const std::vector<double>& body_angles, double roll,
                             double pitch) const;
  // Joint angles for both feet's frames in the torso frame, within the joint
  // limits. `start` (e.g. the last solution) speeds convergence up.
  LegSolution inverse(const Pose& left_foot, const Pose& right_foot,
                      const LegSolution* start = nullptr) const;

  // Writes both legs' angles into `targets` (one per body joint), clamped to
  // the joint limits.
  void writeTargets(const LegSolution& legs, std::vector<double>& targets) const;

  // Where a joint of each part sits in LegAngles (the same for both legs).
  int index(LegJoint part) const { return part_[static_cast<size_t>(part)]; }
  // The foot's link (its last joint's child).
  int footLink(Leg leg) const { return foot_link_[static_cast<size_t>(leg)]; }
  // Body joint indices of a leg's six joints (for commands and sensor frames).
  const std::array<int, 6>& joints(Leg leg) const { return legs_[static_cast<size_t>(leg)].joint; }
  double lower(Leg leg, int i) const { return legs_[static_cast<size_t>(leg)].lower[i]; }
  double upper(Leg leg, int i) const { return legs_[static_cast<size_t>(leg)].upper[i]; }
  double soleDepth() const { return sole_depth_; }  // m, foot frame to the sole
  // The leg's first joint's origin in the torso frame (a Nao: the hip joint centre, where its
  // three hip axes meet; a K1: the hip pitch joint, above the roll and yaw joints).
  Vec3 hip(Leg leg) const { return legs_[static_cast<size_t>(leg)].origin[0]; }

 private:
  // forward() from body joint angles (body joint order, mimics applied).
  Pose forwardFromBody(Leg leg, const std::vector<double>& body_angles) const;

  struct Chain {
    std::array<int, 6> joint{};
    std::array<Vec3, 6> origin{}, axis{};
    std::array<double, 6> lower{}, upper{};
  };
  std::array<Chain, 2> legs_;
  std::array<int, 6> part_{};       // LegJoint -> position in the chain
  std::array<int, 2> foot_link_{};  // left, right
  // shared_[i]: the right leg's joint i mimics the left's (multiplier mimic_[i]).
  std::array<bool, 6> shared_{};
  std::array<double, 6> mimic_{};
  double sole_depth_ = 0.0;
};

}  // namespace simsoccer::agents
