// Position servos for every actuated joint of every robot, as one structure
// of arrays: the hot loop is a straight pass over contiguous doubles.
//
// Model (per joint and physics step of h seconds):
//   tau_pd = kp (target - q) - kd qdot              (the position servo)
//   (a command with its own gains: kp (target - q) + kd (velocity - qdot) + torque,
//   at stiffness 1: setCommand)
//   DC motor envelope with the stiffness s in [0, 1] scaling the drive D = s stall:
//     D (-1 - w/w0) <= tau_motor <= D (1 - w/w0)
//   tau = clamp(tau_pd, envelope) - damping qdot    (the passive damping explicit: it is small)
// Each motor's servo is evaluated one of two ways (the robot YAML's `servo`):
// - explicit: tau_pd from q and qdot at the start of the step, applied as a
//   joint torque. Cheap; stable while h kd / I and h^2 kp / I stay well below
//   2 for every inertia I the joint can move.
// - implicit: backward Euler, tau_pd = kp (target - q') - kd' qdot' at the END
//   of the step, with kd' = max(kd - h kp, 0) so that on a heavy joint it is
//   the explicit torque above. Bullet's constraint solver finds it with the real
//   articulated inertia, contacts included: one soft constraint row per servo
//   (its CFM the spring-damper's compliance, Catto's soft constraints), its
//   impulse bounded by the envelope. Needed for the Nao's legs: with the
//   armature on the links, some joint-space modes of a leg in the air (hip,
//   knee and ankle pitch together) are so light that the explicit kd of
//   0.3 N m s/rad at 5 ms diverged, and a robot getting up flew away.
// The envelope's speed w is the joint speed at the end of the step, predicted
// from a lower bound of the joint's inertia and the load seen in the previous
// steps (low-pass filtered): evaluated at the current speed instead, its slope
// D / w0 (2.9 N m s/rad on a Nao leg) is an explicit damper that is unstable on
// a free-swinging leg at 5 ms and lets a head pass its no-load speed in one
// step; predicted, a loaded joint still gets its full stall torque.
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
  // lower bound of the inertia the joint moves (kg m^2, > 0); `implicit`: the
  // servo's kind at the world's step (Motor::implicitAt).
  size_t add(const Motor& motor, double damping, double lower, double upper, double min_inertia,
             bool implicit);
  size_t size() const { return target_.size(); }

  // Target angles are clamped to the joint limits; stiffness to [0, 1]. The
  // servo runs with its motor's gains (kp, kd at stiffness 1, scaled drive).
  void setTarget(size_t i, double target_rad, double stiffness);
  // A command with its own gains, as a Booster robot's joint command carries
  // them: tau = kp (target - q) + kd (velocity - qdot) + torque, within the
  // motor's envelope at full drive (stiffness 1). kp, kd >= 0 (clamped).
  // It holds until the next setTarget or setCommand.
  void setCommand(size_t i, double target_rad, double velocity, double torque, double kp,
                  double kd);
  double target(size_t i) const { return target_[i]; }
  double stiffness(size_t i) const { return stiffness_[i]; }
  // Motor part of the last step's torque (without passive damping), N m.
  double motorTorque(size_t i) const { return motor_tau_[i]; }
  // The whole torque of the last step: motor plus passive damping, N m.
  double torque(size_t i) const { return motor_tau_[i] + passive_tau_[i]; }
  // Appends every servo's target, stiffness and the state it carries between
  // steps (for state hashes); the commanded gains too, once a setCommand has
  // set any (a world that never used them hashes as before they existed).
  void appendState(std::vector<double>& out) const;
  // Forget the load history of one servo (after a teleport).
  void resetHistory(size_t i);

  bool implicit(size_t i) const { return implicit_[i] != 0; }

  // Stage 1, before the solver, from the joint positions and speeds at the
  // start of a step of dt seconds: every explicit servo's torque, every
  // implicit servo's constraint row, and the torque the caller applies as a
  // joint torque before the solver (appliedTorque): the passive damping plus
  // the explicit servo's torque or the implicit row's feedforward.
  void prepare(std::span<const double> q, std::span<const double> qdot, double dt);
  double appliedTorque(size_t i) const { return passive_tau_[i] + feedforward_[i]; }

  // One servo's soft constraint row for the step prepared: the motor's impulse
  // over the step is dt * feedforward + p, and the solver finds p (N m s) with
  //   qdot' = beta / dt (target - q) - gamma (dt * feedforward + p),
  //   lower <= feedforward + p / dt <= upper.
  // The feedforward (last step's motor torque, within the bounds) is applied
  // as a joint torque before the solver: Bullet starts joint rows from zero
  // impulse, and this way its iterations (solver_iterations, a fixed number)
  // start from the last answer (a warm start) and look for the change.
  // (Measured without it: the stance, sway and walk figures were the same.)
  // active false: limp or explicit, no row.
  struct Row {
    bool active = false;
    double target = 0.0;              // rad
    double beta = 0.0;                // share of the position error removed in one step
    double bias = 0.0;                // rad/s: a commanded velocity and torque's share
    double gamma = 0.0;               // compliance, rad/s per N m s
    double feedforward = 0.0;         // N m
    // The motor torque's bounds from the speed predicted in prepare(), N m
    // (for Bullet's solver, whose bounds are fixed over its iterations).
    double lower = 0.0, upper = 0.0;
    // The envelope at the joint's speed w' at the end of the step, as the
    // engine's solver applies it: drive (-1 - w'/w0) <= motor torque <=
    // drive (1 - w'/w0), w' the speed it solves for.
    double drive = 0.0;        // N m: stiffness x stall torque
    double inv_no_load = 0.0;  // 1 / w0, s/rad

    // That envelope as bounds on an impulse p over a step of h seconds: the
    // joint reaches w' = speed + inv_mass p (speed: without p; inv_mass:
    // J M^-1 J^T) and the motor's impulse is preapplied + p, so
    // lower <= p <= upper; each rad/s that other impulses add to w' lowers
    // both bounds by slope.
    struct ImpulseBounds {
      double lower, upper, slope;
    };
    ImpulseBounds envelope(double h, double inv_mass, double speed, double preapplied) const {
      const double k = h * drive * inv_no_load;  // N m s per rad/s
      const double scale = 1.0 / (1.0 + k * inv_mass);
      const double rest = -preapplied - k * speed;
      return {(-h * drive + rest) * scale, (h * drive + rest) * scale, k * scale};
    }
  };
  Row row(size_t i) const;

  // Stage 3, after the solver: the impulse p the solver applied with
  // implicit servo i's row (N m s; 0 without a row).
  void setRowImpulse(size_t i, double impulse);

  // The motor torque the solver finds for implicit servo i (0 for an explicit
  // one: its torque is motorTorque after prepare) when its joint is alone:
  // inertia `inertia` (kg m^2), no other force, the step prepared. For tests
  // and for reading the model above in one place.
  double solveAlone(size_t i, double q, double qdot, double inertia) const;

 private:
  // The row of servo i this step: an implicit servo with some gain (a pure
  // torque command, kp = kd = 0, is applied as a joint torque).
  bool rowActive(size_t i) const;

  std::vector<double> target_, stiffness_, kp_, kd_, damping_, stall_, inv_no_load_, lower_, upper_,
      min_inertia_, prev_qdot_, load_, motor_tau_, passive_tau_, feedforward_, lo_, hi_;
  // The motor's own gains, and what a command with gains adds.
  std::vector<double> motor_kp_, motor_kd_, target_velocity_, torque_;
  std::vector<unsigned char> has_history_, implicit_;
  bool any_commanded_gains_ = false;
  double dt_ = 0.0;
};

}  // namespace simsoccer::engine
