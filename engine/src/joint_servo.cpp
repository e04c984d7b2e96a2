#include "simsoccer/engine/joint_servo.hpp"

#include <algorithm>
#include <stdexcept>

namespace simsoccer::engine {

size_t JointServoBatch::add(const Motor& motor, double damping, double lower, double upper) {
  if (!(motor.no_load_speed > 0.0)) throw std::invalid_argument("motor no_load_speed must be > 0");
  target_.push_back(std::clamp(0.0, lower, upper));
  stiffness_.push_back(0.0);
  kp_.push_back(motor.kp);
  kd_.push_back(motor.kd);
  damping_.push_back(damping);
  stall_.push_back(motor.stall_torque);
  inv_no_load_.push_back(1.0 / motor.no_load_speed);
  lower_.push_back(lower);
  upper_.push_back(upper);
  return target_.size() - 1;
}

void JointServoBatch::setTarget(size_t i, double target_rad, double stiffness) {
  target_[i] = std::clamp(target_rad, lower_[i], upper_[i]);
  stiffness_[i] = std::clamp(stiffness, 0.0, 1.0);
}

void JointServoBatch::computeTorques(std::span<const double> q, std::span<const double> qdot,
                                     std::span<double> tau) const {
  const size_t n = target_.size();
  for (size_t i = 0; i < n; ++i) {
    const double pd = kp_[i] * (target_[i] - q[i]) - kd_[i] * qdot[i];
    const double drive = stiffness_[i] * stall_[i];
    const double speed_ratio = qdot[i] * inv_no_load_[i];
    const double hi = drive * (1.0 - speed_ratio);
    const double lo = -drive * (1.0 + speed_ratio);
    tau[i] = std::min(std::max(pd, lo), hi) - damping_[i] * qdot[i];
  }
}

}  // namespace simsoccer::engine
