// The SPL GameController's enums and constants (RoboCupGameControlData.h of
// GameController3, docs/reference.md): shared by the referee, which writes
// the packets and the DDS GameState, and the agents, which read them.
#pragma once

#include <cstddef>
#include <cstdint>

#include "simsoccer/protocol/wire.hpp"

namespace simsoccer::protocol {

namespace gc {

constexpr uint16_t kControlPort = 3838;
constexpr uint16_t kReturnPort = 3939;
constexpr uint8_t kControlVersion = 18;
constexpr uint8_t kReturnVersion = 4;
constexpr size_t kMaxPlayers = protocol::kMaxPlayers;
constexpr uint8_t kKickingTeamNone = 255;

enum class Colour : uint8_t {
  Blue = 0,
  Red = 1,
  Yellow = 2,
  Black = 3,
  White = 4,
  Green = 5,
  Orange = 6,
  Purple = 7,
  Brown = 8,
  Gray = 9
};
enum class GamePhase : uint8_t { Normal = 0, PenaltyShoot = 1, Overtime = 2, Timeout = 3 };
enum class State : uint8_t {
  Initial = 0,
  Ready = 1,
  Set = 2,
  Playing = 3,
  Finished = 4,
  Standby = 5
};
enum class SetPlay : uint8_t {
  None = 0,
  GoalKick = 1,
  PushingFreeKick = 2,
  CornerKick = 3,
  KickIn = 4,
  PenaltyKick = 5
};
enum class Penalty : uint8_t {
  None = 0,
  IllegalBallContact = 1,
  PlayerPushing = 2,
  IllegalMotionInSet = 3,
  InactivePlayer = 4,
  IllegalPosition = 5,
  LeavingTheField = 6,
  RequestForPickup = 7,
  LocalGameStuck = 8,
  IllegalPositionInSet = 9,
  PlayerStance = 10,
  IllegalMotionInStandby = 11,
  Substitute = 14,
  Manual = 15
};

}  // namespace gc

}  // namespace simsoccer::protocol
