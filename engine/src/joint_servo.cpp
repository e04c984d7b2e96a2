#include "simsoccer/engine/joint_servo.hpp"

#include <algorithm>
#include <stdexcept>

namespace simsoccer::engine {

namespace {
constexpr double kLoadFilter = 0.1;  // per step: a 50 ms time constant at 5 ms
}  // namespace

size_t JointServoBatch::add(const Motor& motor, double damping, double lower, double upper,
                            double min_inertia) {
  if (!(motor.no_load_speed > 0.0)) throw std::invalid_argument("motor no_load_speed must be > 0");
  if (!(min_inertia > 0.0)) throw std::invalid_argument("servo min_inertia must be > 0");
  target_.push_back(std::clamp(0.0, lower, upper));
  stiffness_.push_back(0.0);
  kp_.push_back(motor.kp);
  kd_.push_back(motor.kd);
  damping_.push_back(damping);
  stall_.push_back(motor.stall_torque);
  inv_no_load_.push_back(1.0 / motor.no_load_speed);
  lower_.push_back(lower);
  upper_.push_back(upper);
  min_inertia_.push_back(min_inertia);
  prev_qdot_.push_back(0.0);
  prev_tau_.push_back(0.0);
  has_history_.push_back(0);
  load_.push_back(0.0);
  motor_tau_.push_back(0.0);
  return target_.size() - 1;
}

void JointServoBatch::setTarget(size_t i, double target_rad, double stiffness) {
  target_[i] = std::clamp(target_rad, lower_[i], upper_[i]);
  stiffness_[i] = std::clamp(stiffness, 0.0, 1.0);
}

void JointServoBatch::appendState(std::vector<double>& out) const {
  for (const auto* v : {&target_, &stiffness_, &prev_qdot_, &prev_tau_, &load_})
    out.insert(out.end(), v->begin(), v->end());
  for (unsigned char h : has_history_) out.push_back(h);
}

void JointServoBatch::resetHistory(size_t i) {
  has_history_[i] = 0;
  load_[i] = 0.0;
}

void JointServoBatch::computeTorques(std::span<const double> q, std::span<const double> qdot,
                                     std::span<double> tau, double dt) {
  const size_t n = target_.size();
  for (size_t i = 0; i < n; ++i) {
    const double w = qdot[i];
    const double pd = kp_[i] * (target_[i] - q[i]) - kd_[i] * w;
    const double drive = stiffness_[i] * stall_[i];
    double motor = 0.0;
    if (drive > 0.0) {
      // Everything but our torque that accelerated the joint last step,
      // low-pass filtered: static loads (gravity, a push) change slowly, and
      // following contact impulses step by step makes the loop unstable.
      if (has_history_[i]) {
        const double seen = min_inertia_[i] * (w - prev_qdot_[i]) / dt - prev_tau_[i];
        load_[i] += kLoadFilter * (seen - load_[i]);
      }
      const double load = load_[i];
      const double k = drive * inv_no_load_[i] * dt / min_inertia_[i];
      const double inv = 1.0 / (1.0 + k);
      const double hi = (drive * (1.0 - w * inv_no_load_[i]) - k * load) * inv;
      const double lo = (-drive * (1.0 + w * inv_no_load_[i]) - k * load) * inv;
      motor = std::min(std::max(pd, lo), hi);
    }
    motor_tau_[i] = motor;
    tau[i] = motor - damping_[i] * w;
    prev_qdot_[i] = w;
    prev_tau_[i] = tau[i];
    has_history_[i] = 1;
  }
}

}  // namespace simsoccer::engine
