// Position servos for every actuated joint of every robot, as one structure
// of arrays: the hot loop is a straight pass over contiguous doubles.
//
// Model (per joint, evaluated every physics step, explicit):
//   tau_pd = kp (target - q) - kd qdot
//   DC motor envelope with the stiffness s in [0, 1] scaling the drive:
//     tau_max = s * stall * (1 - qdot / no_load_speed)
//     tau_min = -s * stall * (1 + qdot / no_load_speed)
//   tau = clamp(tau_pd, tau_min, tau_max) - damping * qdot
// The envelope is what keeps the joint below its no-load speed, and s = 0
// leaves only passive damping (a limp joint), as on the real Nao.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "simsoccer/engine/model.hpp"

namespace simsoccer::engine {

class JointServoBatch {
 public:
  // Appends one servo; returns its index in the batch.
  size_t add(const Motor& motor, double damping, double lower, double upper);
  size_t size() const { return target_.size(); }

  // Target angles are clamped to the joint limits; stiffness to [0, 1].
  void setTarget(size_t i, double target_rad, double stiffness);
  double target(size_t i) const { return target_[i]; }
  double stiffness(size_t i) const { return stiffness_[i]; }

  // tau[i] for every servo from the joint positions and velocities.
  void computeTorques(std::span<const double> q, std::span<const double> qdot,
                      std::span<double> tau) const;

 private:
  std::vector<double> target_, stiffness_, kp_, kd_, damping_, stall_, inv_no_load_, lower_,
      upper_;
};

}  // namespace simsoccer::engine
