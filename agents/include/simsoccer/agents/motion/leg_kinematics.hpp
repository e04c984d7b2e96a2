// Forward and inverse kinematics of a Nao's legs from the robot model's data
// (joint origins, axes and limits), so the H25 and H21 files both work.
//
// Frames: the torso frame (x forward, y left, z up, origin at the torso
// joint frame); a foot's frame is its AnkleRoll joint frame (at the ankle,
// axes aligned with the torso at zero angles), the sole `soleDepth()` below.
//
// The two HipYawPitch hinges share one motor (nao.md 2.4), so the legs are
// not independent: inverse() solves both at once, 11 joints for two foot
// poses (12 numbers), positions first, orientations as close as the shared
// hinge allows. Poses reachable with one HipYawPitch angle (stepping
// straight, or any pair the robot can actually hold) are reached exactly.
#pragma once

#include <array>
#include <vector>

#include "simsoccer/robots/robot_model.hpp"

namespace simsoccer::agents {

using engine::Pose;
using engine::Vec3;

enum class Leg { Left = 0, Right = 1 };

// HipYawPitch, HipRoll, HipPitch, KneePitch, AnklePitch, AnkleRoll (rad).
using LegAngles = std::array<double, 6>;

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
  // Joint angles for both feet's frames in the torso frame, within the joint
  // limits. `start` (e.g. the last solution) speeds convergence up.
  LegSolution inverse(const Pose& left_foot, const Pose& right_foot,
                      const LegSolution* start = nullptr) const;

  // Writes both legs' angles into `targets` (one per body joint), clamped to
  // the joint limits.
  void writeTargets(const LegSolution& legs, std::vector<double>& targets) const;

  // Body joint indices of a leg's six joints (for commands and sensor frames).
  const std::array<int, 6>& joints(Leg leg) const { return legs_[static_cast<size_t>(leg)].joint; }
  double lower(Leg leg, int i) const { return legs_[static_cast<size_t>(leg)].lower[i]; }
  double upper(Leg leg, int i) const { return legs_[static_cast<size_t>(leg)].upper[i]; }
  double soleDepth() const { return sole_depth_; }  // m, foot frame to the sole
  // Hip joint centre in the torso frame.
  Vec3 hip(Leg leg) const { return legs_[static_cast<size_t>(leg)].origin[0]; }

 private:
  struct Chain {
    std::array<int, 6> joint{};
    std::array<Vec3, 6> origin{}, axis{};
    std::array<double, 6> lower{}, upper{};
  };
  std::array<Chain, 2> legs_;
  double sole_depth_ = 0.0;
};

}  // namespace simsoccer::agents
