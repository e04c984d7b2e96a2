#include "simsoccer/agents/motion/walk_engine.hpp"

#include <algorithm>
#include <cmath>

#include "smoothstep.hpp"

namespace simsoccer::agents {
namespace {

// The share of a step at either end when the swing foot is still near the ground (its lift is
// a sine of the phase: under a third of the apex).
const double kTurnMargin = 0.1;

Pose2 compose(const Pose2& a, double dx, double dy, double dyaw) {
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  return {a.x + c * dx - s * dy, a.y + s * dx + c * dy, a.yaw + dyaw};
}

Pose2 lerp(const Pose2& a, const Pose2& b, double t) {
  return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.yaw + (b.yaw - a.yaw) * t};
}

}  // namespace

WalkEngine::WalkEngine(const robots::RobotModel& model, const WalkParameters& parameters)
    : kinematics_(model), p_(parameters) {
  foot_[0] = {0.0, 0.5 * p_.step_width, 0.0};
  foot_[1] = {0.0, -0.5 * p_.step_width, 0.0};
}

void WalkEngine::setVelocity(double forward, double left, double turn) {
  // Per-step averages, inside the diamond (L1 ball) of the limits: full
  // speed forward, sideways and turning cannot be had at once.
  Eigen::Vector3d w(forward * p_.step_period, left * p_.step_period, turn * p_.step_period);
  const Eigen::Vector3d limit(w.x() >= 0 ? p_.max_forward : p_.max_backward, 0.5 * p_.max_side,
                              0.5 * p_.max_turn);
  const double r = w.cwiseQuotient(limit).lpNorm<1>();  // combined steps are harder: a diamond
  if (r > 1.0) w /= r;
  wanted_ = w;
  if (!walking_) {
    walking_ = true;
    stopping_ = false;
    phase_ = 0.0;
    support_ = Leg::Right;  // the left foot steps first (the right one after a weight shift)
    shifting_ = stood_for_ < p_.start_shift_time;
    startStep();
  }
  stopping_ = false;
}

void WalkEngine::stop(bool settle) {
  if (walking_) stopping_ = true;
  settling_ = settle;
}

void WalkEngine::startStep() {
  const int swing = support_ == Leg::Left ? 1 : 0;
  if (shifting_) {  // the sway alone: the body and the feet stay where they are
    step_.setZero();
    body_start_ = body_end_ = body_;
    swing_start_ = swing_end_ = foot_[swing];
    return;
  }
  const double side = swing == 0 ? 1.0 : -1.0;  // +1: the left foot swings
  // The per-step average command ramps towards the wanted one.
  const Eigen::Vector3d want = stopping_ ? Eigen::Vector3d::Zero() : wanted_;
  const bool on_spot = want.head<2>().isZero() && average_.head<2>().isZero();
  const double max_turn = on_spot && p_.max_turn_on_spot > 0.0 ? p_.max_turn_on_spot : p_.max_turn;
  const double max_turn_accel =
      on_spot && p_.max_turn_accel_on_spot > 0.0 ? p_.max_turn_accel_on_spot : p_.max_turn_accel;
  const Eigen::Vector3d max_change(p_.max_accel, p_.max_side_accel, max_turn_accel);
  average_ += (want - average_).cwiseMax(-max_change).cwiseMin(max_change);
  step_.x() = average_.x();
  // Sideways and turning only on the steps that open the legs that way (the
  // left foot leads to the left), twice the average; the other foot closes up.
  step_.y() = (average_.y() * side > 0) ? 2.0 * average_.y() : 0.0;
  // Turning, with the heading hold: the IMU's yaw against the commanded heading.
  intended_yaw_ += average_.z();
  const double measured = yaw_ - yaw_offset_;
  const double error = std::remainder(intended_yaw_ - measured, 2 * M_PI);
  const bool settling = stopping_ && settling_ && average_.isZero(1e-6) &&
                        std::abs(error) < p_.stop_heading_tolerance;
  const double turn =
      settling ? 0.0
               : std::clamp(2.0 * average_.z() + p_.heading_gain * error, -max_turn, max_turn);
  step_.z() = (turn * side > 0) ? turn : 0.0;
  body_start_ = body_;
  body_end_ = compose(body_, p_.forward_scale * step_.x(), step_.y(), step_.z());
  odometry_ = compose(odometry_, step_.x(), step_.y(), step_.z());
  swing_start_ = foot_[swing];
  swing_end_ = compose(body_end_, 0.0, side * 0.5 * p_.step_width, 0.0);
}

LegSolution WalkEngine::solve(const Pose2& body, double sway_y, const Pose2& left,
                              const Pose2& right, double left_lift, double right_lift) {
  // Torso pose in the odometry frame (3D), the feet relative to it.
  const Pose2 torso = compose(body, p_.torso_offset, sway_y, 0.0);
  Pose t = Pose::Identity();
  t.translation() = Vec3(torso.x, torso.y, p_.ankle_height);
  t.rotate(Eigen::AngleAxisd(torso.yaw, Vec3::UnitZ()));
  t.rotate(Eigen::AngleAxisd(p_.torso_lean, Vec3::UnitY()));
  const Pose inv = t.inverse();
  auto foot = [&](const Pose2& f, double lift) {
    Pose x = Pose::Identity();
    x.translation() = Vec3(f.x, f.y, lift);
    x.rotate(Eigen::AngleAxisd(f.yaw, Vec3::UnitZ()));
    return inv * x;
  };
  const LegSolution s = kinematics_.inverse(foot(left, left_lift), foot(right, right_lift),
                                            have_last_ ? &last_ : nullptr);
  last_ = s;
  have_last_ = true;
  return s;
}

void WalkEngine::standWhereTheFeetAre(const std::vector<double>& joints) {
  if (walking_) return;
  const auto left = kinematics_.footAgainst(Leg::Left, Leg::Right, joints);
  if (!left) return;
  // In the right foot's frame: the left foot, and the body between them.
  const Pose2 middle{0.5 * left->x(), 0.5 * left->y(), 0.5 * left->z()};
  const double c = std::cos(middle.yaw), s = std::sin(middle.yaw);
  auto fromMiddle = [&](double x, double y, double yaw) {  // a foot relative to the body
    const double dx = x - middle.x, dy = y - middle.y;
    return compose(body_, c * dx + s * dy, -s * dx + c * dy, yaw - middle.yaw);
  };
  foot_[0] = fromMiddle(left->x(), left->y(), left->z());
  foot_[1] = fromMiddle(0.0, 0.0, 0.0);
}

void WalkEngine::easeIn(const std::vector<double>& from, double t, std::vector<double>& targets) {
  std::vector<double> stance = from;
  kinematics_.writeTargets(solve(body_, 0.0, foot_[0], foot_[1], 0.0, 0.0), stance);
  const double a = std::clamp(t / kEaseTime, 0.0, 1.0);
  for (size_t j = 0; j < targets.size(); ++j) targets[j] = (1 - a) * from[j] + a * stance[j];
}

void WalkEngine::update(double dt, const WalkSensors& imu, std::vector<double>& targets) {
  gyro_filtered_ += p_.gyro_smoothing * (imu.gyro - gyro_filtered_);
  if (!yaw_known_) {
    yaw_offset_ = imu.yaw - body_.yaw;
    intended_yaw_ = body_.yaw;
    yaw_known_ = true;
  }
  yaw_ = imu.yaw;
  if (walking_) {
    phase_ += dt / p_.step_period;
    const double lean_to_support = support_ == Leg::Left ? -imu.roll : imu.roll;
    if (phase_ >= 1.0 && !shifting_ && lean_to_support > p_.support_lean &&
        held_ < p_.max_support_hold) {
      phase_ = 1.0;  // both feet down until the lean is back
      held_ += dt;
    } else if (phase_ >= 1.0) {
      held_ = 0.0;
      // The swing foot is down: it becomes the support.
      const int swing = support_ == Leg::Left ? 1 : 0;
      foot_[swing] = swing_end_;
      body_ = body_end_;
      support_ = support_ == Leg::Left ? Leg::Right : Leg::Left;
      phase_ -= 1.0;
      const bool feet_together =
          average_.norm() < 1e-6 && std::abs(step_.y()) < 1e-6 && std::abs(step_.z()) < 1e-6;
      if (stopping_ && feet_together) {  // stopped: stand
        walking_ = stopping_ = false;
        phase_ = 0.0;
        step_.setZero();
        average_.setZero();
      } else {
        shifting_ = false;
        startStep();
      }
    }
  }
  stood_for_ = walking_ ? 0.0 : stood_for_ + dt;
  LegSolution s;
  if (!walking_) {
    s = solve(body_, 0.0, foot_[0], foot_[1], 0.0, 0.0);
  } else {
    const int swing = support_ == Leg::Left ? 1 : 0;
    const double ph = phase_;
    const Pose2 body = lerp(body_start_, body_end_, ph);
    const double support_side = support_ == Leg::Left ? 1.0 : -1.0;
    const double sway = support_side * p_.sway * std::sin(M_PI * ph);
    Pose2 feet[2] = {foot_[0], foot_[1]};
    feet[swing] = lerp(swing_start_, swing_end_, smoothstep(ph));
    // The swing foot turns only while it is off the ground: turned as it lifted off and set
    // down, it twisted against the carpet and the robot turned back (the K1 turned 0.61 rad/s
    // commanding 0.8, now 0.69).
    const double turning = std::clamp((ph - kTurnMargin) / (1.0 - 2.0 * kTurnMargin), 0.0, 1.0);
    feet[swing].yaw = swing_start_.yaw + (swing_end_.yaw - swing_start_.yaw) * smoothstep(turning);
    double lift[2] = {0.0, 0.0};
    // Shifting the weight, both feet stay down: no lift, and no sag to make up for.
    const double single_support = shifting_ ? 0.0 : 1.0;
    lift[swing] = single_support * p_.foot_lift * std::sin(M_PI * ph);
    s = solve(body, sway, feet[0], feet[1], lift[0], lift[1]);
    LegAngles& support_q = support_ == Leg::Left ? s.left : s.right;
    support_q[static_cast<size_t>(kinematics_.index(LegJoint::HipRoll))] +=
        single_support * support_side * p_.hip_roll_compensation * std::sin(M_PI * ph);
  }
  // Balance: the support ankle (both while standing) leans against the
  // torso's rotation rate.
  for (int leg = 0; leg < 2; ++leg) {
    LegAngles& q = leg == 0 ? s.left : s.right;
    if (walking_ && static_cast<int>(support_) != leg) continue;
    q[static_cast<size_t>(kinematics_.index(LegJoint::AnklePitch))] +=
        p_.ankle_pitch_gyro * gyro_filtered_.y();
    q[static_cast<size_t>(kinematics_.index(LegJoint::AnkleRoll))] +=
        p_.ankle_roll_gyro * gyro_filtered_.x();
  }
  kinematics_.writeTargets(s, targets);
}

}  // namespace simsoccer::agents
