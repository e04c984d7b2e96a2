#include "simsoccer/agents/motion/motion_controller.hpp"

#include <algorithm>
#include <cmath>

namespace simsoccer::agents {

const char* motionStateName(MotionState s) {
  switch (s) {
    case MotionState::Easing:
      return "easing";
    case MotionState::Stance:
      return "stance";
    case MotionState::Walking:
      return "walking";
    case MotionState::Kicking:
      return "kicking";
    case MotionState::Blocking:
      return "blocking";
    case MotionState::Diving:
      return "diving";
    case MotionState::SittingDown:
      return "sitting_down";
    case MotionState::Sitting:
      return "sitting";
    case MotionState::StandingUp:
      return "standing_up";
    case MotionState::Falling:
      return "falling";
    case MotionState::Lying:
      return "lying";
    case MotionState::GettingUp:
      return "getting_up";
  }
  return "?";
}

MotionController::MotionController(const robots::RobotModel& model, KeyframeMotions motions,
                                   const WalkParameters& walk, const KickParameters& kick,
                                   const FallDetectorParameters& fall)
    : model_(model),
      motions_(std::move(motions)),
      walk_parameters_(walk),
      kick_parameters_(kick),
      fall_(fall),
      walk_(model, walk),
      kick_(model, walk, kick),
      targets_(model.pose("stand")) {
  head_yaw_ = model.body->jointIndex("HeadYaw");
  head_pitch_ = model.body->jointIndex("HeadPitch");
  for (const robots::LegChain& leg : model.legs)
    leg_joints_.insert(leg_joints_.end(), leg.joints.begin(), leg.joints.end());
}

void MotionController::restart() {
  restart_ = true;
}

void MotionController::restartFrom(const std::vector<double>& measured,
                                   const MotionSensors& sensors) {
  restart_ = false;
  // The fall detector's filtered "up" and tilt from the IMU's angles: it
  // still holds the state from before the restart (a robot the referee took
  // out of a get-up and set down upright read as falling, went soft and sagged).
  const double cp = std::cos(sensors.pitch);
  gravity_ = 9.81 * Vec3(-std::sin(sensors.pitch), cp * std::sin(sensors.roll),
                         cp * std::cos(sensors.roll));
  tilt_ = std::acos(std::clamp(cp * std::cos(sensors.roll), -1.0, 1.0));
  if (state_ == MotionState::SittingDown || state_ == MotionState::Sitting) {
    // Restarted while sitting (the next half's Initial): up by the stand-up
    // motion, not an ease from the crouch.
    standUp(measured);
    return;
  }
  ease_from_ = measured;
  walk_ = WalkEngine(model_, walk_parameters_);
  walk_.standWhereTheFeetAre(measured);
  kick_ = KickEngine(model_, walk_parameters_, kick_parameters_);
  player_ = KeyframePlayer();
  targets_ = measured;
  stiffness_ = 1.0;
  enter(MotionState::Easing);
}

bool MotionController::upright() const {
  return tilt_ < fall_.upright_tilt;
}

bool MotionController::placedOnItsFeet(const MotionSensors& sensors,
                                       const std::vector<double>& measured, double rate) const {
  bool targets_far = true;  // during a motion: its targets far from the stand pose
  switch (state_) {
    case MotionState::Falling:
    case MotionState::Lying:
      if (rate >= fall_.lying_rate) return false;  // soft, it lies still where it is put
      targets_far = false;
      break;
    case MotionState::GettingUp:
      break;
    case MotionState::Diving:
      if (state_time_ <= 0.3) return false;  // still in the stance it dived from
      break;
    default:
      return false;
  }
  if (std::abs(sensors.roll) > fall_.upright_tilt || std::abs(sensors.pitch) > fall_.upright_tilt)
    return false;
  const std::vector<double>& stand = model_.pose("stand");
  double off_measured = 0.0, off_targets = 0.0;  // rad, the largest over the legs
  for (int j : leg_joints_) {
    const size_t k = static_cast<size_t>(j);
    off_measured = std::max(off_measured, std::abs(measured[k] - stand[k]));
    off_targets = std::max(off_targets, std::abs(targets_[k] - stand[k]));
  }
  return off_measured < 0.2 && (!targets_far || off_targets > 0.4);
}

void MotionController::enter(MotionState s) {
  state_ = s;
  state_time_ = 0.0;
  still_for_ = 0.0;
  standing_for_ = 0.0;
}

void MotionController::startKeyframes(MotionState s, const KeyframeMotion& motion,
                                      const std::vector<double>& measured, double dt) {
  enter(s);
  player_.start(motion, measured);
  player_.update(dt, targets_, stiffness_);
}

void MotionController::standUp(const std::vector<double>& measured) {
  enter(MotionState::StandingUp);
  player_.start(motions_.stand_up, measured);
}

void MotionController::easeIntoStance() {
  ease_from_ = targets_;
  walk_ = WalkEngine(model_, walk_parameters_);
  enter(MotionState::Easing);
}

void measuredJointAngles(const robots::RobotModel& model, std::span<const float> position,
                         std::vector<double>& q) {
  if (std::all_of(position.begin(), position.end(), [](float v) { return v == 0.0f; })) {
    q = model.pose("stand");
    return;
  }
  q.assign(model.body->joints.size(), 0.0);
  for (size_t a = 0; a < model.actuators.size() && a < position.size(); ++a)
    if (model.actuators[a].kind == robots::Actuator::Kind::Joint)
      q[static_cast<size_t>(model.actuators[a].index)] = position[a];
  model.body->applyMimic(q);
}

Eigen::Vector2d MotionController::feetCentre(const MotionSensors& sensors) const {
  std::vector<double> measured;
  measuredJointAngles(model_, sensors.position, measured);
  return walk_.kinematics().feetCentre(measured, sensors.roll, sensors.pitch);
}

void MotionController::update(double dt, const MotionSensors& sensors, const MotionRequest& request,
                              std::span<float> position, std::span<float> stiffness) {
  // The direction of "up" in the torso frame from the accelerometer, low-passed
  // (steps and kicks shake it; a fall takes ~0.5 s).
  gravity_ = 0.8 * gravity_ + 0.2 * sensors.accel;
  tilt_ = gravity_.norm() > 1e-6 ? std::acos(std::clamp(gravity_.z() / gravity_.norm(), -1.0, 1.0))
                                 : 0.0;
  const double rate = sensors.gyro.norm();
  state_time_ += dt;
  std::vector<double> measured;
  measuredJointAngles(model_, sensors.position, measured);

  if (restart_) restartFrom(measured, sensors);
  if (placedOnItsFeet(sensors, measured, rate)) {
    // Stiff in the stance at once: one more period of a get-up's targets
    // knocks it over, and soft it sinks. The filtered "up" still says lying
    // (the next period would count a fall): restarted from the IMU's angles.
    restartFrom(measured, sensors);
  }
  // On its feet by intent: a tilt past falling_tilt is a fall (a dive is
  // meant to end on the ground; the rest are already down).
  const bool normal = state_ != MotionState::Diving && state_ != MotionState::Falling &&
                      state_ != MotionState::Lying && state_ != MotionState::GettingUp;
  if (normal && tilt_ > fall_.falling_tilt) {
    ++counters_.falls;
    enter(MotionState::Falling);
  }

  switch (state_) {
    case MotionState::Easing:
      stiffness_ = 1.0;
      walk_.easeIn(ease_from_, state_time_, targets_);
      if (state_time_ >= WalkEngine::kEaseTime) enter(MotionState::Stance);
      break;
    case MotionState::Stance:
    case MotionState::Walking:
      stiffness_ = 1.0;
      if (request.kind == MotionRequest::Kind::Block) {
        // No time to stop the walk first: the block starts from the joints as
        // they are (its first frame is short and low, which steadies the robot).
        ++counters_.blocks;
        startKeyframes(MotionState::Blocking, motions_.block, measured, dt);
        break;
      }
      if (request.kind == MotionRequest::Kind::Dive) {
        ++counters_.dives;
        startKeyframes(MotionState::Diving,
                       request.side == Leg::Left ? motions_.dive_left : motions_.dive_right,
                       measured, dt);
        break;
      }
      standing_for_ = state_ == MotionState::Stance && !walk_.walking() ? standing_for_ + dt : 0.0;
      if (request.kind == MotionRequest::Kind::Kick && state_ == MotionState::Stance &&
          !walk_.walking() && standing_for_ >= kick_parameters_.ready_time - 1e-9) {
        kick_.start(request.kick_foot, measured);
        ++counters_.kicks;
        enter(MotionState::Kicking);
        kick_.update(dt, sensors.gyro, targets_, {sensors.roll, sensors.pitch});
        break;
      }
      if (request.kind == MotionRequest::Kind::Sit && state_ == MotionState::Stance &&
          !walk_.walking()) {
        ++counters_.sits;
        startKeyframes(MotionState::SittingDown, motions_.sit_down, measured, dt);
        break;
      }
      if (request.kind == MotionRequest::Kind::Walk)
        walk_.setVelocity(request.forward, request.left, request.turn);
      else  // stand; before a kick or sitting down, come to rest (the sway must not keep
            // the heading hold stepping: a K1 lined up at the ball stepped on for good)
        walk_.stop(request.kind == MotionRequest::Kind::Sit ||
                   request.kind == MotionRequest::Kind::Kick);
      walk_.update(dt, {sensors.gyro, sensors.roll, sensors.yaw}, targets_);
      state_ = walk_.walking() ? MotionState::Walking : MotionState::Stance;
      break;
    case MotionState::Kicking:
      kick_.update(dt, sensors.gyro, targets_, {sensors.roll, sensors.pitch});
      if (!kick_.active()) enter(MotionState::Stance);
      break;
    case MotionState::Diving:
      // Meant to end on the ground: not a fall. Lying afterwards, the fall
      // detector's rules apply (soft, then the get-up if it is on).
      player_.update(dt, targets_, stiffness_);
      if (!player_.active()) enter(MotionState::Lying);
      break;
    case MotionState::Blocking:
      player_.update(dt, targets_, stiffness_);
      if (!player_.active()) easeIntoStance();  // back up
      break;
    case MotionState::SittingDown:
    case MotionState::Sitting:
      // Sitting, it rests in the motion's last frame at its stiffness (the
      // servos hold the crouch without fighting it: cool joints while the
      // game is over). Another request stands it up from where it is, also
      // half-way down (a Finished that lasts one period, between a match's
      // end and its shoot-out).
      if (request.kind == MotionRequest::Kind::Sit) {
        if (state_ == MotionState::SittingDown) {
          player_.update(dt, targets_, stiffness_);
          if (!player_.active()) enter(MotionState::Sitting);
        }
        break;
      }
      standUp(measured);
      [[fallthrough]];
    case MotionState::StandingUp:
      player_.update(dt, targets_, stiffness_);
      if (!player_.active()) easeIntoStance();
      break;
    case MotionState::Falling:
    case MotionState::Lying:
      // Soft joints that keep their current angles: no servo fights the impact.
      targets_ = measured;
      stiffness_ = fall_.safe_stiffness;
      if (tilt_ > fall_.lying_tilt && rate < fall_.lying_rate)
        still_for_ += dt;
      else
        still_for_ = 0.0;
      if (tilt_ < fall_.upright_tilt && rate < fall_.lying_rate &&
          (state_ == MotionState::Lying || state_time_ > 0.5)) {
        // Upright again: it caught itself, or it was picked up and put back
        // on its feet (a referee's placement): back to the stance.
        restart_ = true;
        break;
      }
      if (still_for_ >= fall_.lying_time && fall_.get_up) {
        // Up in the torso frame: -x lying on the front (chest down), +x on the back.
        const bool front = gravity_.x() < 0.0;
        startKeyframes(MotionState::GettingUp, front ? motions_.get_up_front : motions_.get_up_back,
                       measured, dt);
      } else if (state_ == MotionState::Falling && tilt_ > fall_.lying_tilt) {
        state_ = MotionState::Lying;
      }
      break;
    case MotionState::GettingUp:
      player_.update(dt, targets_, stiffness_);
      if (!player_.active()) {
        if (upright()) {
          ++counters_.get_ups;
          easeIntoStance();
        } else if (const KeyframeMotion::Ends ends = player_.motion()->ends;
                   (ends == KeyframeMotion::Ends::Front && gravity_.x() < 0.0) ||
                   (ends == KeyframeMotion::Ends::Back && gravity_.x() > 0.0)) {
          // Rolled onto the side the motion meant: lying, so the fall detector
          // starts the get-up from that side once it is still.
          enter(MotionState::Lying);
        } else {
          ++counters_.failed_get_ups;
          enter(MotionState::Falling);
        }
      }
      break;
  }

  // Head: the behaviour's targets, within the joints' limits, unless falling.
  const auto& joints = model_.body->joints;
  const bool soft = state_ == MotionState::Falling || state_ == MotionState::Lying;
  if (!soft && state_ != MotionState::GettingUp) {
    if (head_yaw_ >= 0)
      targets_[static_cast<size_t>(head_yaw_)] =
          std::clamp(request.head_yaw, joints[static_cast<size_t>(head_yaw_)].lower,
                     joints[static_cast<size_t>(head_yaw_)].upper);
    if (head_pitch_ >= 0)
      targets_[static_cast<size_t>(head_pitch_)] =
          std::clamp(request.head_pitch, joints[static_cast<size_t>(head_pitch_)].lower,
                     joints[static_cast<size_t>(head_pitch_)].upper);
  }
  for (size_t a = 0; a < model_.actuators.size() && a < position.size(); ++a) {
    const auto& act = model_.actuators[a];
    if (act.kind != robots::Actuator::Kind::Joint) {
      position[a] = 0.0f;
      stiffness[a] = soft ? 0.0f : static_cast<float>(stiffness_);
      continue;
    }
    const int j = act.index;
    position[a] = static_cast<float>(targets_[static_cast<size_t>(j)]);
    const bool head = j == head_yaw_ || j == head_pitch_;
    stiffness[a] =
        static_cast<float>(head && !soft ? std::min(stiffness_, fall_.head_stiffness) : stiffness_);
  }
}

}  // namespace simsoccer::agents
