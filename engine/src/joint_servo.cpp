#include "simsoccer/engine/joint_servo.hpp"

#include <algorithm>
#include <stdexcept>

namespace simsoccer::engine {

namespace {
constexpr double kLoadFilter = 0.1;  // per step: a 50 ms time constant at 5 ms
}  // namespace

size_t JointServoBatch::add(const Motor& motor, double damping, double lower, double upper,
                            double min_inertia, bool implicit) {
  if (!(motor.no_load_speed > 0.0)) throw std::invalid_argument("motor no_load_speed must be > 0");
  if (!(min_inertia > 0.0)) throw std::invalid_argument("servo min_inertia must be > 0");
  if (!(motor.kp >= 0.0) || !(motor.kd >= 0.0) || !(motor.kp + motor.kd > 0.0))
    throw std::invalid_argument("motor kp and kd must be >= 0 and not both 0");
  target_.push_back(std::clamp(0.0, lower, upper));
  stiffness_.push_back(0.0);
  kp_.push_back(motor.kp);
  kd_.push_back(motor.kd);
  motor_kp_.push_back(motor.kp);
  motor_kd_.push_back(motor.kd);
  target_velocity_.push_back(0.0);
  torque_.push_back(0.0);
  damping_.push_back(damping);
  stall_.push_back(motor.stall_torque);
  inv_no_load_.push_back(1.0 / motor.no_load_speed);
  lower_.push_back(lower);
  upper_.push_back(upper);
  min_inertia_.push_back(min_inertia);
  prev_qdot_.push_back(0.0);
  has_history_.push_back(0);
  implicit_.push_back(implicit ? 1 : 0);
  load_.push_back(0.0);
  motor_tau_.push_back(0.0);
  passive_tau_.push_back(0.0);
  feedforward_.push_back(0.0);
  lo_.push_back(0.0);
  hi_.push_back(0.0);
  return target_.size() - 1;
}

void JointServoBatch::setTarget(size_t i, double target_rad, double stiffness) {
  target_[i] = std::clamp(target_rad, lower_[i], upper_[i]);
  stiffness_[i] = std::clamp(stiffness, 0.0, 1.0);
  kp_[i] = motor_kp_[i];
  kd_[i] = motor_kd_[i];
  target_velocity_[i] = 0.0;
  torque_[i] = 0.0;
}

void JointServoBatch::setCommand(size_t i, double target_rad, double velocity, double torque,
                                 double kp, double kd) {
  target_[i] = std::clamp(target_rad, lower_[i], upper_[i]);
  stiffness_[i] = 1.0;
  kp_[i] = std::max(kp, 0.0);
  kd_[i] = std::max(kd, 0.0);
  target_velocity_[i] = velocity;
  torque_[i] = torque;
  any_commanded_gains_ = true;
}

void JointServoBatch::appendState(std::vector<double>& out) const {
  for (const auto* v : {&target_, &stiffness_, &prev_qdot_, &load_, &motor_tau_})
    out.insert(out.end(), v->begin(), v->end());
  for (unsigned char h : has_history_) out.push_back(h);
  if (any_commanded_gains_)
    for (const auto* v : {&kp_, &kd_, &target_velocity_, &torque_})
      out.insert(out.end(), v->begin(), v->end());
}

bool JointServoBatch::rowActive(size_t i) const {
  return implicit_[i] && stiffness_[i] > 0.0 && kp_[i] + kd_[i] > 0.0;
}

void JointServoBatch::resetHistory(size_t i) {
  has_history_[i] = 0;
  load_[i] = 0.0;
  motor_tau_[i] = 0.0;
}

void JointServoBatch::prepare(std::span<const double> q, std::span<const double> qdot, double dt) {
  dt_ = dt;
  const size_t n = target_.size();
  for (size_t i = 0; i < n; ++i) {
    const double w = qdot[i];
    const double drive = stiffness_[i] * stall_[i];
    double lo = 0.0, hi = 0.0;
    if (drive > 0.0) {
      // Everything but our torque that accelerated the joint last step,
      // low-pass filtered: static loads (gravity, a push) change slowly, and
      // following contact impulses step by step makes the loop unstable.
      if (has_history_[i]) {
        // (motor and passive torques still those of last step: torque(i))
        const double seen = min_inertia_[i] * (w - prev_qdot_[i]) / dt - torque(i);
        load_[i] += kLoadFilter * (seen - load_[i]);
      }
      const double load = load_[i];
      const double k = drive * inv_no_load_[i] * dt / min_inertia_[i];
      const double inv = 1.0 / (1.0 + k);
      hi = (drive * (1.0 - w * inv_no_load_[i]) - k * load) * inv;
      lo = (-drive * (1.0 + w * inv_no_load_[i]) - k * load) * inv;
    }
    lo_[i] = lo;
    hi_[i] = hi;
    passive_tau_[i] = -damping_[i] * w;
    if (implicit_[i] && kp_[i] + kd_[i] > 0.0) {
      feedforward_[i] = drive > 0.0 ? std::clamp(motor_tau_[i], lo, hi) : 0.0;
    } else {
      // (target_velocity_ and torque_ are 0 unless a command set them: the
      // position servo's torque is computed as it always was.)
      double pd = kp_[i] * (target_[i] - q[i]) - kd_[i] * w;
      if (target_velocity_[i] != 0.0 || torque_[i] != 0.0)
        pd += kd_[i] * target_velocity_[i] + torque_[i];
      feedforward_[i] = motor_tau_[i] = drive > 0.0 ? std::clamp(pd, lo, hi) : 0.0;
    }
    prev_qdot_[i] = w;
    has_history_[i] = 1;
  }
}

JointServoBatch::Row JointServoBatch::row(size_t i) const {
  Row r;
  if (!rowActive(i) || !(dt_ > 0.0)) return r;
  // Backward Euler of tau = kp (target - q') - kd' qdot' with q' = q + dt qdot'
  // and the impulse p = dt tau: qdot' = beta / dt (target - q) - gamma p, where
  // c = kd' + dt kp. For a heavy joint (qdot' ~ qdot) that is
  // tau = kp (target - q) - c qdot: the explicit servo's torque when
  // kd' = kd - dt kp, so the servo damps as its kd says (backward Euler's own
  // damping dt kp included; at least that much).
  const double c = std::max(kd_[i], dt_ * kp_[i]);
  r.active = true;
  r.target = target_[i];
  r.beta = dt_ * kp_[i] / c;
  r.gamma = 1.0 / (dt_ * c);
  // A command's velocity and torque: the target moves at the velocity over
  // the step, so tau = kp (target + dt velocity - q') + kd' (velocity - qdot')
  // + torque = ... + c velocity + torque - c qdot': qdot' gains velocity +
  // torque / c (for a heavy joint the explicit law, kd (velocity - qdot)).
  if (target_velocity_[i] != 0.0 || torque_[i] != 0.0)
    r.bias = target_velocity_[i] + torque_[i] / c;
  r.feedforward = feedforward_[i];
  r.lower = lo_[i];
  r.upper = hi_[i];
  r.drive = stiffness_[i] * stall_[i];
  r.inv_no_load = inv_no_load_[i];
  return r;
}

void JointServoBatch::setRowImpulse(size_t i, double impulse) {
  motor_tau_[i] = feedforward_[i] + impulse / dt_;
}

double JointServoBatch::solveAlone(size_t i, double q, double qdot, double inertia) const {
  const Row r = row(i);
  if (!r.active) return 0.0;
  // qdot' = qdot + P / I  and  qdot' = beta / dt (target - q) - gamma P, with P
  // the whole impulse (feedforward included), bounded by the torque-speed
  // line at qdot': P / dt <= drive (1 - qdot' / w0), and likewise below.
  const double p = (r.beta / dt_ * (r.target - q) + r.bias - qdot) / (1.0 / inertia + r.gamma);
  const Row::ImpulseBounds b = r.envelope(dt_, 1.0 / inertia, qdot, 0.0);
  return std::clamp(p, b.lower, b.upper) / dt_;
}

}  // namespace simsoccer::engine
