#include "simsoccer/agents/motion/kick_engine.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "smoothstep.hpp"

namespace simsoccer::agents {
namespace {

// One keyframe: torso shift (fraction of the full shift), the kicking foot
// forward (m), up (m) and out (fraction of swing_out), and the time to reach it.
struct Key {
  double shift, along, up, out, time;
};

}  // namespace

KickEngine::KickEngine(const robots::RobotModel& model, const WalkParameters& stance,
                       const KickParameters& parameters)
    : kinematics_(model), stance_(stance), p_(parameters) {}

void KickEngine::start(Leg foot) {
  foot_ = foot;
  t_ = 0.0;
  active_ = true;
}

double KickEngine::duration() const {
  return p_.shift_time + p_.lift_time + p_.swing_time + p_.retract_time + p_.lower_time +
         p_.return_time + p_.settle_time;
}

void KickEngine::update(double dt, const Vec3& gyro, std::vector<double>& targets) {
  const std::array<Key, 8> keys{{{0, 0, 0, 0, 0},
                                 {1, 0, 0, 0, p_.shift_time},
                                 {1, -p_.draw_back, p_.lift, 1, p_.lift_time},
                                 {1, p_.reach, p_.swing_height, 1, p_.swing_time},
                                 {1, 0, p_.lift, 0, p_.retract_time},
                                 {1, 0, 0, 0, p_.lower_time},
                                 {0, 0, 0, 0, p_.return_time},
                                 {0, 0, 0, 0, p_.settle_time}}};
  if (active_) t_ += dt;
  // Where in the keyframes we are.
  double shift = 0, along = 0, up = 0, outward = 0, t = t_;
  bool done = true;
  for (size_t k = 1; k < keys.size(); ++k) {
    if (t <= keys[k].time) {
      // The swing itself is linear (fast and straight); the rest is smooth.
      const double a = k == 3 ? t / keys[k].time : smoothstep(t / keys[k].time);
      shift = keys[k - 1].shift + a * (keys[k].shift - keys[k - 1].shift);
      along = keys[k - 1].along + a * (keys[k].along - keys[k - 1].along);
      up = keys[k - 1].up + a * (keys[k].up - keys[k - 1].up);
      outward = keys[k - 1].out + a * (keys[k].out - keys[k - 1].out);
      done = false;
      break;
    }
    t -= keys[k].time;
  }
  if (done) active_ = false;
  // The stance: feet side by side, the torso shifted towards the support foot.
  const double side = foot_ == Leg::Left ? 1.0 : -1.0;  // the kicking foot's side
  Pose torso = Pose::Identity();
  torso.translation() = Vec3(stance_.torso_offset, -side * shift * p_.shift, stance_.ankle_height);
  const Pose inv = torso.inverse();
  auto foot = [&](double y, double dx, double dz) {
    Pose f = Pose::Identity();
    f.translation() = Vec3(dx, y, dz);
    return inv * f;
  };
  const double half = 0.5 * stance_.step_width;
  const Pose kicking = foot(side * (half + outward * p_.swing_out), along, up);
  const Pose support = foot(-side * half, 0.0, 0.0);
  const LegSolution s = foot_ == Leg::Left
                            ? kinematics_.inverse(kicking, support, have_last_ ? &last_ : nullptr)
                            : kinematics_.inverse(support, kicking, have_last_ ? &last_ : nullptr);
  last_ = s;
  have_last_ = true;
  LegSolution out = s;
  // The support leg: hip roll against the sag, ankle against the torso's rotation.
  LegAngles& sq = foot_ == Leg::Left ? out.right : out.left;
  const auto at = [&](LegJoint part) { return static_cast<size_t>(kinematics_.index(part)); };
  sq[at(LegJoint::HipRoll)] += (foot_ == Leg::Left ? -1.0 : 1.0) * p_.hip_roll_compensation * shift;
  sq[at(LegJoint::AnklePitch)] += stance_.ankle_pitch_gyro * gyro.y();
  sq[at(LegJoint::AnkleRoll)] += stance_.ankle_roll_gyro * gyro.x();
  kinematics_.writeTargets(out, targets);
}

}  // namespace simsoccer::agents
