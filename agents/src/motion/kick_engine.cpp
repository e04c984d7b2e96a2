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

void KickEngine::start(Leg foot, const std::vector<double>& joints) {
  foot_ = foot;
  t_ = 0.0;
  calm_for_ = 0.0;
  have_tilt_start_ = false;
  active_ = true;
  const Leg support = foot == Leg::Left ? Leg::Right : Leg::Left;
  const double side = foot == Leg::Left ? 1.0 : -1.0;
  start_offset_ = Eigen::Vector3d(0.0, side * stance_.step_width, 0.0);
  if (joints.empty()) return;
  if (const auto stood = kinematics_.footAgainst(foot, support, joints)) start_offset_ = *stood;
}

double KickEngine::duration() const {
  return p_.shift_time + p_.lift_time + p_.swing_time + p_.retract_time + p_.lower_time +
         p_.return_time + p_.settle_time;
}

void KickEngine::update(double dt, const Vec3& gyro, std::vector<double>& targets,
                        const TorsoTilt& tilt) {
  if (!have_tilt_start_) {
    tilt_start_ = tilt;
    have_tilt_start_ = true;
  }
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
  bool both_feet_down = true;  // the kicking foot not yet lifted, or lowered again
  double replaced = 1;         // the kicking foot's rest: 0 where it stood, 1 the gait's stance
  bool done = true;
  for (size_t k = 1; k < keys.size(); ++k) {
    if (t <= keys[k].time) {
      // The swing itself is linear (fast and straight); the rest is smooth.
      const double a = k == 3 ? t / keys[k].time : smoothstep(t / keys[k].time);
      shift = keys[k - 1].shift + a * (keys[k].shift - keys[k - 1].shift);
      along = keys[k - 1].along + a * (keys[k].along - keys[k - 1].along);
      up = keys[k - 1].up + a * (keys[k].up - keys[k - 1].up);
      outward = keys[k - 1].out + a * (keys[k].out - keys[k - 1].out);
      // Put in the gait's stance while it is lifted, before the swing (the swing goes where the
      // behaviour aimed, and the walk starts again from the stance it assumes).
      replaced = k < 2 ? 0.0 : k == 2 ? smoothstep(t / keys[k].time) : 1.0;
      both_feet_down = k <= 1 || k >= 6;
      done = false;
      break;
    }
    t -= keys[k].time;
  }
  // The tilt reflex, once the kicking foot is down again (traced in K1 5 v 5 games: a kick into
  // a ball pressed against an opponent's feet, or into its legs, left the robot tilted 0.3 rad
  // onto one foot's outer edge, the other foot in the air; the stance held it there, the torso
  // turning too slowly for the calm wait, and after 0.5 s it toppled).
  auto beyond = [&](double a) {
    return std::copysign(std::max(0.0, std::abs(a) - p_.tilt_deadband), a);
  };
  const double excess_roll = beyond(tilt.roll - tilt_start_.roll);
  const double excess_pitch = beyond(tilt.pitch - tilt_start_.pitch);
  const bool reflex = p_.tilt_gain > 0.0 && both_feet_down && t_ > p_.shift_time;
  const bool tilted = reflex && (excess_roll != 0.0 || excess_pitch != 0.0);
  // Done with the keyframes: holding the stance until the torso is calm (and upright).
  calm_for_ = gyro.norm() < p_.calm_rate && !tilted ? calm_for_ + dt : 0.0;
  if (done && (p_.calm_rate <= 0.0 || calm_for_ >= p_.calm_time - 1e-9 ||
               t_ >= duration() + p_.calm_wait - 1e-9))
    active_ = false;
  // The stance: the support foot at its place in the gait's stance, the kicking foot where it
  // stood until it is lifted, the torso from over the feet's middle shifted towards the support
  // foot.
  const double side = foot_ == Leg::Left ? 1.0 : -1.0;  // the kicking foot's side
  const double half = 0.5 * stance_.step_width;
  const Eigen::Vector3d gait(0.0, side * stance_.step_width, 0.0);
  const Eigen::Vector3d rest = start_offset_ + replaced * (gait - start_offset_);
  const Eigen::Vector3d middle(0.5 * rest.x(), -side * half + 0.5 * rest.y(), 0.5 * rest.z());
  Pose torso = Pose::Identity();
  torso.translation() =
      Vec3(stance_.torso_offset + (1 - shift) * middle.x(),
           (1 - shift) * middle.y() - side * shift * p_.shift, stance_.ankle_height);
  torso.rotate(Eigen::AngleAxisd((1 - shift) * middle.z(), Vec3::UnitZ()));
  if (reflex) {  // the torso moved towards the raised side (roll > 0: leaning right)
    torso.translation().x() -= p_.tilt_gain * excess_pitch;
    torso.translation().y() += p_.tilt_gain * excess_roll;
  }
  const Pose inv = torso.inverse();
  auto foot = [&](double x, double y, double yaw, double dz) {
    Pose f = Pose::Identity();
    f.translation() = Vec3(x, y, dz);
    f.rotate(Eigen::AngleAxisd(yaw, Vec3::UnitZ()));
    return inv * f;
  };
  // Along the support foot (the aim), out sideways from it.
  const Pose kicking =
      foot(rest.x() + along, -side * half + rest.y() + side * outward * p_.swing_out, rest.z(), up);
  const Pose support = foot(0.0, -side * half, 0.0, 0.0);
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
  if (both_feet_down) {  // standing on both: both ankles, as the walk's stance
    LegAngles& kq = foot_ == Leg::Left ? out.left : out.right;
    kq[at(LegJoint::AnklePitch)] += stance_.ankle_pitch_gyro * gyro.y();
    kq[at(LegJoint::AnkleRoll)] += stance_.ankle_roll_gyro * gyro.x();
  }
  kinematics_.writeTargets(out, targets);
}

}  // namespace simsoccer::agents
