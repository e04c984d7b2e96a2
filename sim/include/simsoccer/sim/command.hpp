// Joint commands on their way into the world: one checked, quantised form
// (RobotCommand), the one place every command is checked (CommandGate), and
// the interface behind which every source of commands plugs into the period
// (agents over DDS, agents in this process, a match log, scripted tests).
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "simsoccer/referee/gamecontroller.hpp"
#include "simsoccer/world/perception.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::sim {

// Targets (rad) and stiffnesses (0..1) in the robot's actuator order, at the
// resolution the physics gets and the match log keeps.
struct RobotCommand {
  std::array<double, world::kActuators> position{}, stiffness{};
  // A command with its own servo gains (a Booster robot's joint command, its
  // CUSTOM mode): per actuator tau = kp (position - q) + kd (velocity - qdot)
  // + torque, at full drive (stiffness 1). Otherwise the robot's own servo
  // gains scaled by the stiffness.
  bool with_gains = false;
  std::array<double, world::kActuators> velocity{}, torque{}, kp{}, kd{};
  bool operator==(const RobotCommand&) const = default;
};

// Why a command was refused (None: it was accepted).
enum class CommandFault : uint8_t {
  None,
  WrongSize,          // not one value per actuator
  NotFinite,          // a NaN or an infinity
  StiffnessRange,     // outside 0..1
  PositionRange,      // beyond the joint's limits by more than the margin
  ActuatorRange,      // a non-joint actuator (LEDs...) beyond +-10
  GainRange,          // a servo gain negative or absurd (kp > 10^4, kd > 10^3)
  VelocityRange,      // a target velocity beyond +-100 rad/s
  TorqueRange,        // a feedforward torque beyond +-1000 N m
};
const char* faultName(CommandFault f);

// The one choke point: every command, whatever its source, is checked and
// quantised here before it can reach the world. Thread-safe (a transport may
// check on its receive thread); counts what it refused per robot.
class CommandGate {
 public:
  // `position_margin`: rad beyond a joint's limits before a target is refused.
  CommandGate(const world::World& world, double position_margin);

  // The command, checked and quantised, or the reason it is refused (counted).
  std::optional<RobotCommand> check(world::RobotId r, std::span<const double> position,
                                    std::span<const double> stiffness,
                                    CommandFault* fault = nullptr);
  std::optional<RobotCommand> check(world::RobotId r, std::span<const float> position,
                                    std::span<const float> stiffness,
                                    CommandFault* fault = nullptr);
  // A command with its own gains (RobotCommand::with_gains), one entry per
  // actuator of the robot (its model's count, not the frame's 25 slots).
  struct ServoSpans {
    std::span<const float> position, velocity, torque, kp, kd;
  };
  std::optional<RobotCommand> checkServo(world::RobotId r, const ServoSpans& command,
                                         CommandFault* fault = nullptr);
  uint64_t rejected(world::RobotId r) const { return rejected_.at(r).load(); }
  CommandFault lastFault(world::RobotId r) const { return last_fault_.at(r).load(); }

 private:
  template <typename T>
  std::optional<RobotCommand> checkAny(world::RobotId r, std::span<const T> position,
                                       std::span<const T> stiffness, CommandFault* fault);
  struct Limits {
    std::array<double, world::kActuators> lower{}, upper{};
    std::array<bool, world::kActuators> joint{};  // a joint (else a hand, an LED...)
  };
  std::optional<RobotCommand> refuse(world::RobotId r, CommandFault why, CommandFault* fault);
  std::vector<Limits> limits_;  // per robot, margin included
  std::vector<size_t> actuator_count_;  // per robot, its model's
  std::vector<std::atomic<uint64_t>> rejected_;
  std::vector<std::atomic<CommandFault>> last_fault_;
};

// A source's answer for one robot in one period.
enum class Answer : uint8_t {
  None,   // this source does not drive the robot, or has nothing new (real time)
  Given,  // `command` holds a checked command
  Missed  // the robot's driver did not answer in time: it keeps its last command
};
struct CommandSlot {
  Answer answer = Answer::None;
  RobotCommand command;
};

// What sources see at the start of a period (stage observe): the world after
// the last step, its perception, and the game state when a referee runs.
struct Observation {
  uint64_t tick = 0;
  double time = 0.0;
  const world::World* world = nullptr;
  const world::PerceptionSystem* perception = nullptr;  // null: perception off
  const referee::ControlData* game = nullptr;           // null: no referee
  int left_team = 0;                                    // the team game->teams[0] describes
  // Periods after this one that the answers collected for it act in: 0 serial, 1 pipelined.
  int actuation_delay = 0;
};

class CommandSource {
 public:
  virtual ~CommandSource() = default;
  // Stage observe: the state of `o.tick` is ready; send it to the drivers
  // (publish frames, or run an agent).
  virtual void observe(const Observation& o) = 0;
  // Stage collect: the answers to tick `tick` for the robots this source
  // drives, checked through `gate` (a lockstep source waits here). Slots of
  // robots it does not drive stay Answer::None.
  virtual void collect(uint64_t tick, CommandGate& gate, std::span<CommandSlot> slots) = 0;
  // After the step (commands applied, world stepped): per-period bookkeeping.
  virtual void afterStep(const world::World&) {}
  // Team messages the robots this source drives have sent for team index
  // `team` so far (the officials count them against the message budget).
  virtual uint64_t teamMessagesSent(int /*team*/) const { return 0; }
};

}  // namespace simsoccer::sim
