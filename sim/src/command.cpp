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
  }
  return "?";
}

namespace {
// Non-joint actuators (LEDs, ...) take values in a small range; beyond it a
// command is garbage.
constexpr double kActuatorBound = 10.0;
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
