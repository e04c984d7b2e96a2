// RoboCupGameControlData v19, the HSL GameController's (a fork of
// GameController3; RoboCup-HumanoidSoccerLeague/GameController,
// game_controller_msgs/headers/RoboCupGameControlData.h): the same header
// part as v18 with competitionPhase replaced by competitionType and
// competitionType's byte by `stopped`; RobotInfo grows warnings and cautions.
#include <cstring>

#include "packet_io.hpp"
#include "simsoccer/referee/gamecontroller.hpp"

namespace simsoccer::referee {

namespace hsl {
namespace {
// HSL codes (v19 header).
enum SetPlay : uint8_t {
  kNone = 0,
  kDirectFreeKick = 1,
  kIndirectFreeKick = 2,
  kPenaltyKick = 3,
  kThrowIn = 4,
  kGoalKick = 5,
  kCornerKick = 6
};
enum Penalty : uint8_t {
  kNoPenalty = 0,
  kIllegalPositioning = 1,
  kMotionInSet = 2,
  kLocalGameStuck = 3,
  kIncapableRobot = 4,
  kPickUp = 5,
  kBallHolding = 6,
  kLeavingTheField = 7,
  kPlayingWithArmsHands = 8,
  kPushing = 9,
  kSentOff = 10,
  kSubstitute = 11
};
}  // namespace

uint8_t setPlayFromSpl(uint8_t spl) {
  switch (static_cast<gc::SetPlay>(spl)) {
    case gc::SetPlay::GoalKick: return kGoalKick;
    case gc::SetPlay::PushingFreeKick: return kDirectFreeKick;  // a foul: a direct free kick
    case gc::SetPlay::CornerKick: return kCornerKick;
    case gc::SetPlay::KickIn: return kThrowIn;  // the HSL's name for the ball over the touchline
    case gc::SetPlay::PenaltyKick: return kPenaltyKick;
    default: return kNone;
  }
}

uint8_t setPlayToSpl(uint8_t hsl) {
  switch (hsl) {
    case kDirectFreeKick:
    case kIndirectFreeKick: return static_cast<uint8_t>(gc::SetPlay::PushingFreeKick);
    case kPenaltyKick: return static_cast<uint8_t>(gc::SetPlay::PenaltyKick);
    case kThrowIn: return static_cast<uint8_t>(gc::SetPlay::KickIn);
    case kGoalKick: return static_cast<uint8_t>(gc::SetPlay::GoalKick);
    case kCornerKick: return static_cast<uint8_t>(gc::SetPlay::CornerKick);
    default: return static_cast<uint8_t>(gc::SetPlay::None);
  }
}

uint8_t penaltyFromSpl(uint8_t spl) {
  using P = gc::Penalty;
  switch (static_cast<P>(spl)) {
    case P::None: return kNoPenalty;
    case P::IllegalBallContact: return kPlayingWithArmsHands;
    case P::PlayerPushing: return kPushing;
    case P::IllegalMotionInSet:
    case P::IllegalMotionInStandby: return kMotionInSet;
    case P::InactivePlayer: return kIncapableRobot;
    case P::IllegalPosition:
    case P::IllegalPositionInSet:
    case P::PlayerStance: return kIllegalPositioning;
    case P::LeavingTheField: return kLeavingTheField;
    case P::RequestForPickup:
    case P::Manual: return kPickUp;
    case P::LocalGameStuck: return kLocalGameStuck;
    case P::Substitute: return kSubstitute;
  }
  return kPickUp;
}

uint8_t penaltyToSpl(uint8_t hsl) {
  using P = gc::Penalty;
  switch (hsl) {
    case kNoPenalty: return static_cast<uint8_t>(P::None);
    case kIllegalPositioning: return static_cast<uint8_t>(P::IllegalPosition);
    case kMotionInSet: return static_cast<uint8_t>(P::IllegalMotionInSet);
    case kLocalGameStuck: return static_cast<uint8_t>(P::LocalGameStuck);
    case kIncapableRobot: return static_cast<uint8_t>(P::InactivePlayer);
    case kPickUp: return static_cast<uint8_t>(P::RequestForPickup);
    case kBallHolding:
    case kPlayingWithArmsHands: return static_cast<uint8_t>(P::IllegalBallContact);
    case kLeavingTheField: return static_cast<uint8_t>(P::LeavingTheField);
    case kPushing: return static_cast<uint8_t>(P::PlayerPushing);
    case kSubstitute: return static_cast<uint8_t>(P::Substitute);
    default: return static_cast<uint8_t>(P::Manual);  // sent off: out for the game
  }
}
}  // namespace hsl

std::array<uint8_t, hsl::kControlSize> encodeHsl(const ControlData& d) {
  std::array<uint8_t, hsl::kControlSize> b{};
  Out o(b);
  o.bytes(d.true_data ? "RGTD" : "RGme", 4);
  o.u8(hsl::kControlVersion);
  o.u8(d.packet_number);
  o.u8(d.players_per_team);
  o.u8(d.competition_type);
  o.u8(d.stopped);
  o.u8(d.game_phase);
  // No Standby in the HSL: a robot sees Initial until Ready.
  o.u8(d.state == static_cast<uint8_t>(gc::State::Standby) ? static_cast<uint8_t>(gc::State::Initial)
                                                             : d.state);
  o.u8(hsl::setPlayFromSpl(d.set_play));
  o.u8(d.first_half);
  o.u8(d.kicking_team);
  o.i16(d.secs_remaining);
  o.i16(d.secondary_time);
  for (const TeamInfo& t : d.teams) writeTeam(o, t, true);
  return b;
}

ControlData decodeHsl(std::span<const uint8_t> bytes) {
  if (bytes.size() != hsl::kControlSize)
    throw PacketError("control packet v19: " + std::to_string(bytes.size()) + " bytes, expected " +
                      std::to_string(hsl::kControlSize));
  const bool rgme = std::memcmp(bytes.data(), "RGme", 4) == 0;
  const bool rgtd = std::memcmp(bytes.data(), "RGTD", 4) == 0;
  if (!rgme && !rgtd) throw PacketError("control packet: header is not RGme or RGTD");
  In in(bytes);
  for (int i = 0; i < 4; ++i) in.u8();
  if (const uint8_t version = in.u8(); version != hsl::kControlVersion)
    throw PacketError("control packet: version " + std::to_string(version) + ", expected 19");
  ControlData d;
  d.true_data = rgtd;
  d.packet_number = in.u8();
  d.players_per_team = in.u8();
  d.competition_type = in.u8();
  d.stopped = in.u8();
  d.game_phase = in.u8();
  d.state = in.u8();
  const uint8_t set_play = in.u8();
  d.first_half = in.u8();
  d.kicking_team = in.u8();
  d.secs_remaining = in.i16();
  d.secondary_time = in.i16();
  for (TeamInfo& t : d.teams) t = readTeam(in, true);
  if (d.competition_type > 2)
    throw PacketError("control packet v19: competitionType " + std::to_string(d.competition_type));
  if (d.game_phase > 3) throw PacketError("control packet: gamePhase " + std::to_string(d.game_phase));
  if (d.state > 4) throw PacketError("control packet v19: state " + std::to_string(d.state));
  if (set_play > 6) throw PacketError("control packet v19: setPlay " + std::to_string(set_play));
  d.set_play = hsl::setPlayToSpl(set_play);
  return d;
}

std::vector<uint8_t> encodeControl(const ControlData& data, int version) {
  if (version == hsl::kControlVersion) {
    const auto b = encodeHsl(data);
    return {b.begin(), b.end()};
  }
  const auto b = encode(data);
  return {b.begin(), b.end()};
}

ControlData decodeAnyControl(std::span<const uint8_t> bytes, int* version) {
  if (bytes.size() < 5) throw PacketError("control packet: " + std::to_string(bytes.size()) + " bytes");
  const int v = bytes[4];
  if (version) *version = v;
  return v == hsl::kControlVersion ? decodeHsl(bytes) : decodeControl(bytes);
}

}  // namespace simsoccer::referee
