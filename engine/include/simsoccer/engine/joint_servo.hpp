// Position servos for every actuated joint of every robot, as one structure
// of arrays: the hot loop is a straight pass over contiguous doubles.
//
// Model (per joint, evaluated every physics step):
//   tau_pd = kp (target - q) - kd qdot                      (the position servo)
//   DC motor envelope with the stiffness s in [0, 1] scaling the drive D = s stall:
//     D (-1 - w/w0) <= tau_motor <= D (1 - w/w0)
//   tau = clamp(tau_pd, envelope) - damping qdot
// The envelope's speed w is the joint speed at the END of the step, predicted
// (semi-implicitly) from a lower bound of the joint's inertia and the load
// seen in the previous steps (low-pass filtered). Evaluated at the current speed instead, the
// envelope's slope D / w0 (2.9 N m s/rad on a Nao leg) is an explicit damper
// that is unstable on a free-swinging leg at 5 ms and lets a head reach more
// than its no-load speed in one step; predicted, a loaded joint still gets
// its full stall torque and no joint drives itself past its no-load speed.
// s = 0 leaves only passive damping (a limp joint), as on the real Nao.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::engine {

class JointServoBatch {
 public:
  // Appends one servo; returns its index in the batch. `min_inertia` is a
  // lower bound of the inertia the joint moves (kg m^2, > 0).
  size_t add(const Motor& motor, double damping, double lower, double upper, double min_inertia);
  size_t size() const { return target_.size(); }

  // Target angles are clamped to the joint limits; stiffness to [0, 1].
  void setTarget(size_t i, double target_rad, double stiffness);
  double target(size_t i) const { return target_[i]; }
  double stiffness(size_t i) const { return stiffness_[i]; }
  // Motor part of the last computed torque (without passive damping), N m.
  double motorTorque(size_t i) const { return motor_tau_[i]; }
  // Appends every servo's target, stiffness and the state it carries between
  // steps (for state hashes).
  void appendState(std::vector<double>& out) const;
  // Forget the load history of one servo (after a teleport).
  void resetHistory(size_t i);

  // tau[i] for every servo from the joint positions and velocities, for a
  // step of dt seconds; remembers speed and torque for the next step.
  void computeTorques(std::span<const double> q, std::span<const double> qdot,
                      std::span<double> tau, double dt);

 private:
  std::vector<double> target_, stiffness_, kp_, kd_, damping_, stall_, inv_no_load_, lower_, upper_,
      min_inertia_, prev_qdot_, prev_tau_, load_, motor_tau_;
  std::vector<unsigned char> has_history_;
};

}  // namespace simsoccer::engine
