#include "simsoccer/sim/command.hpp"

#include <cmath>

#include "simsoccer/world/match_log.hpp"

namespace simsoccer::sim {

const char* faultName(CommandFault f) {
  switch (f) {
    case CommandFault::None:
      return "none";
    case CommandFault::WrongSize:
      return "not one value per actuator";
    case CommandFault::NotFinite:
      return "a value is not finite";
    case CommandFault::StiffnessRange:
      return "a stiffness is outside 0..1";
    case CommandFault::PositionRange:
      return "a target is beyond its joint's limits";
    case CommandFault::ActuatorRange:
      return "a non-joint actuator value is beyond +-10";
    case CommandFault::GainRange:
      return "a servo gain is negative or beyond kp 10000 N m/rad, kd 1000 N m s/rad";
    case CommandFault::VelocityRange:
      return "a target velocity is beyond +-100 rad/s";
    case CommandFault::TorqueRange:
      return "a feedforward torque is beyond +-1000 N m";
  }
  return "?";
}

namespace {
// Non-joint actuators (LEDs, ...) take values in a small range; beyond it a
// command is garbage.
constexpr double kActuatorBound = 10.0;
// Beyond these a servo command is garbage (a real motor's envelope clamps
// what it can do long before).
constexpr double kMaxKp = 1e4, kMaxKd = 1e3, kMaxVelocity = 100.0, kMaxTorque = 1e3;
}  // namespace

CommandGate::CommandGate(const world::World& world, double position_margin)
    : rejected_(world.robotCount()), last_fault_(world.robotCount()) {
  for (world::RobotId r = 0; r < world.robotCount(); ++r) {
    const auto& model = *world.robot(r).model;
    Limits l;
    for (size_t a = 0; a < world::kActuators; ++a) {
      l.lower[a] = -kActuatorBound;
      l.upper[a] = kActuatorBound;
      if (a < model.actuators.size() &&
          model.actuators[a].kind == robots::Actuator::Kind::Joint) {
        const auto& joint = model.body->joints[static_cast<size_t>(model.actuators[a].index)];
        l.lower[a] = joint.lower - position_margin;
        l.upper[a] = joint.upper + position_margin;
        l.joint[a] = true;
      }
    }
    limits_.push_back(l);
    actuator_count_.push_back(model.actuators.size());
    rejected_[r] = 0;
    last_fault_[r] = CommandFault::None;
  }
}

template <typename T>
std::optional<RobotCommand> CommandGate::checkAny(world::RobotId r, std::span<const T> position,
                                                  std::span<const T> stiffness,
                                                  CommandFault* fault) {
  CommandFault why = CommandFault::None;
  const Limits& l = limits_.at(r);
  if (position.size() != world::kActuators || stiffness.size() != world::kActuators) {
    why = CommandFault::WrongSize;
  } else {
    for (size_t a = 0; a < world::kActuators && why == CommandFault::None; ++a) {
      const double p = static_cast<double>(position[a]), k = static_cast<double>(stiffness[a]);
      if (!std::isfinite(p) || !std::isfinite(k))
        why = CommandFault::NotFinite;
      else if (k < 0.0 || k > 1.0)
        why = CommandFault::StiffnessRange;
      else if (const double q = world::quantizeCommand(p); q < l.lower[a] || q > l.upper[a])
        // The quantised target, as it will be applied (and logged): a logged
        // command always passes this check again when it is replayed.
        why = l.joint[a] ? CommandFault::PositionRange : CommandFault::ActuatorRange;
    }
  }
  if (fault) *fault = why;
  if (why != CommandFault::None) {
    ++rejected_[r];
    last_fault_[r] = why;
    return std::nullopt;
  }
  RobotCommand c;
  for (size_t a = 0; a < world::kActuators; ++a) {
    c.position[a] = world::quantizeCommand(static_cast<double>(position[a]));
    c.stiffness[a] = world::quantizeStiffness(static_cast<double>(stiffness[a]));
  }
  return c;
}

std::optional<RobotCommand> CommandGate::check(world::RobotId r, std::span<const double> position,
                                               std::span<const double> stiffness,
                                               CommandFault* fault) {
  return checkAny(r, position, stiffness, fault);
}

std::optional<RobotCommand> CommandGate::check(world::RobotId r, std::span<const float> position,
                                               std::span<const float> stiffness,
                                               CommandFault* fault) {
  return checkAny(r, position, stiffness, fault);
}

}  // namespace simsoccer::sim

namespace simsoccer::sim {

std::optional<RobotCommand> CommandGate::refuse(world::RobotId r, CommandFault why,
                                                CommandFault* fault) {
  if (fault) *fault = why;
  ++rejected_[r];
  last_fault_[r] = why;
  return std::nullopt;
}

std::optional<RobotCommand> CommandGate::checkServo(world::RobotId r, const ServoSpans& c,
                                                    CommandFault* fault) {
  const Limits& l = limits_.at(r);
  const size_t n = actuator_count_.at(r);
  for (const auto* part : {&c.position, &c.velocity, &c.torque, &c.kp, &c.kd})
    if (part->size() != n) return refuse(r, CommandFault::WrongSize, fault);
  RobotCommand out;
  out.with_gains = true;
  for (size_t a = 0; a < n; ++a) {
    const double p = c.position[a], v = c.velocity[a], t = c.torque[a], kp = c.kp[a],
                 kd = c.kd[a];
    if (!std::isfinite(p) || !std::isfinite(v) || !std::isfinite(t) || !std::isfinite(kp) ||
        !std::isfinite(kd))
      return refuse(r, CommandFault::NotFinite, fault);
    if (kp < 0.0 || kd < 0.0 || kp > kMaxKp || kd > kMaxKd)
      return refuse(r, CommandFault::GainRange, fault);
    if (std::abs(v) > kMaxVelocity) return refuse(r, CommandFault::VelocityRange, fault);
    if (std::abs(t) > kMaxTorque) return refuse(r, CommandFault::TorqueRange, fault);
    const double q = world::quantizeCommand(p);
    if (q < l.lower[a] || q > l.upper[a])
      return refuse(r, l.joint[a] ? CommandFault::PositionRange : CommandFault::ActuatorRange,
                    fault);
    out.position[a] = q;
    out.stiffness[a] = 1.0;
    out.velocity[a] = v;
    out.torque[a] = t;
    out.kp[a] = kp;
    out.kd[a] = kd;
  }
  if (fault) *fault = CommandFault::None;
  return out;
}

}  // namespace simsoccer::sim
