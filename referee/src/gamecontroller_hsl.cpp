// RoboCupGameControlData v19 and v20, the HSL GameController's (a fork of GameController3;
// RoboCup-HumanoidSoccerLeague/GameController, game_controller_msgs/headers/
// RoboCupGameControlData.h and game_controller_msgs/dissectors/robocup_gc.lua): the same header
// part as v18 with competitionPhase replaced by competitionType and competitionType's byte by
// `stopped`; RobotInfo is penalty, secsTillUnpenalised, warnings (v19 only) and cautions.
#include <cstring>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "packet_io.hpp"
#include "simsoccer/referee/gamecontroller.hpp"

namespace simsoccer::referee {

namespace hsl {
namespace {
// HSL codes (the same in v19 and v20).
enum SetPlay : uint8_t {
  kNone = 0,
  kDirectFreeKick = 1,
  kIndirectFreeKick = 2,
  kPenaltyKick = 3,
  kThrowIn = 4,
  kGoalKick = 5,
  kCornerKick = 6
};
// The HSL's penalties by name; their codes differ between v19 and v20.
enum class Penalty {
  None,
  IllegalPositioning,
  MotionInSet,
  MotionInStop,  // v20 only
  LocalGameStuck,
  IncapableRobot,
  PickUp,
  BallHolding,
  LeavingTheField,
  PlayingWithArmsHands,
  Pushing,
  Cautioned,  // v20 only
  SentOff,
  Substitute
};
// Code -> penalty, per version (v20: RoboCupGameControlData.h v20; v19: its v19).
constexpr Penalty kPenalties20[] = {Penalty::None,
                                    Penalty::IllegalPositioning,
                                    Penalty::MotionInSet,
                                    Penalty::MotionInStop,
                                    Penalty::LocalGameStuck,
                                    Penalty::IncapableRobot,
                                    Penalty::PickUp,
                                    Penalty::BallHolding,
                                    Penalty::LeavingTheField,
                                    Penalty::PlayingWithArmsHands,
                                    Penalty::Pushing,
                                    Penalty::Cautioned,
                                    Penalty::SentOff,
                                    Penalty::Substitute};
constexpr Penalty kPenalties19[] = {Penalty::None,
                                    Penalty::IllegalPositioning,
                                    Penalty::MotionInSet,
                                    Penalty::LocalGameStuck,
                                    Penalty::IncapableRobot,
                                    Penalty::PickUp,
                                    Penalty::BallHolding,
                                    Penalty::LeavingTheField,
                                    Penalty::PlayingWithArmsHands,
                                    Penalty::Pushing,
                                    Penalty::SentOff,
                                    Penalty::Substitute};

std::span<const Penalty> penaltyCodes(int version) {
  if (version == kVersion19) return kPenalties19;
  return kPenalties20;
}

uint8_t codeOf(Penalty p, int version) {
  const auto codes = penaltyCodes(version);
  for (size_t i = 0; i < codes.size(); ++i)
    if (codes[i] == p) return static_cast<uint8_t>(i);
  return 0;  // not reached: every penalty sent has a code in both
}
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

uint8_t penaltyFromSpl(uint8_t spl, int version) {
  using P = gc::Penalty;
  Penalty h = Penalty::PickUp;
  switch (static_cast<P>(spl)) {
    case P::None:
      h = Penalty::None;
      break;
    case P::IllegalBallContact:
      h = Penalty::PlayingWithArmsHands;
      break;
    case P::PlayerPushing:
      h = Penalty::Pushing;
      break;
    case P::IllegalMotionInSet:
    case P::IllegalMotionInStandby:
      h = Penalty::MotionInSet;
      break;
    case P::InactivePlayer:
      h = Penalty::IncapableRobot;
      break;
    case P::IllegalPosition:
    case P::IllegalPositionInSet:
    case P::PlayerStance:
      h = Penalty::IllegalPositioning;
      break;
    case P::LeavingTheField:
      h = Penalty::LeavingTheField;
      break;
    case P::RequestForPickup:
    case P::Manual:
      h = Penalty::PickUp;
      break;
    case P::LocalGameStuck:
      h = Penalty::LocalGameStuck;
      break;
    case P::Substitute:
      h = Penalty::Substitute;
      break;
  }
  return codeOf(h, version);
}

uint8_t penaltyToSpl(uint8_t code, int version) {
  using P = gc::Penalty;
  const auto codes = penaltyCodes(version);
  if (code >= codes.size())
    throw PacketError("control packet v" + std::to_string(version) + ": penalty " +
                      std::to_string(code));
  P p = P::Manual;  // sent off (out for the game), cautioned: the GameController's to lift
  switch (codes[code]) {
    case Penalty::None:
      p = P::None;
      break;
    case Penalty::IllegalPositioning:
      p = P::IllegalPosition;
      break;
    case Penalty::MotionInSet:
    case Penalty::MotionInStop:
      p = P::IllegalMotionInSet;
      break;
    case Penalty::LocalGameStuck:
      p = P::LocalGameStuck;
      break;
    case Penalty::IncapableRobot:
      p = P::InactivePlayer;
      break;
    case Penalty::PickUp:
      p = P::RequestForPickup;
      break;
    case Penalty::BallHolding:
    case Penalty::PlayingWithArmsHands:
      p = P::IllegalBallContact;
      break;
    case Penalty::LeavingTheField:
      p = P::LeavingTheField;
      break;
    case Penalty::Pushing:
      p = P::PlayerPushing;
      break;
    case Penalty::Substitute:
      p = P::Substitute;
      break;
    case Penalty::Cautioned:
    case Penalty::SentOff:
      break;
  }
  return static_cast<uint8_t>(p);
}
}  // namespace hsl

std::vector<uint8_t> encodeHsl(const ControlData& d, int version) {
  if (version != hsl::kVersion19 && version != hsl::kVersion20)
    throw std::invalid_argument("HSL GameController version " + std::to_string(version) +
                                ": 19 or 20");
  std::vector<uint8_t> b(hsl::controlSize(version));
  Out o(b);
  o.bytes(d.true_data ? "RGTD" : "RGme", 4);
  o.u8(static_cast<uint8_t>(version));
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
  for (const TeamInfo& t : d.teams) writeTeam(o, t, version);
  return b;
}

ControlData decodeHsl(std::span<const uint8_t> bytes) {
  if (bytes.size() < 5)
    throw PacketError("control packet: " + std::to_string(bytes.size()) + " bytes");
  const int version = bytes[4];
  if (version != hsl::kVersion19 && version != hsl::kVersion20)
    throw PacketError("control packet: version " + std::to_string(version) + ", expected 19 or 20");
  const std::string v = "control packet v" + std::to_string(version) + ": ";
  if (bytes.size() != hsl::controlSize(version))
    throw PacketError(v + std::to_string(bytes.size()) + " bytes, expected " +
                      std::to_string(hsl::controlSize(version)));
  const bool rgme = std::memcmp(bytes.data(), "RGme", 4) == 0;
  const bool rgtd = std::memcmp(bytes.data(), "RGTD", 4) == 0;
  if (!rgme && !rgtd) throw PacketError("control packet: header is not RGme or RGTD");
  In in(bytes);
  for (int i = 0; i < 5; ++i) in.u8();
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
  for (TeamInfo& t : d.teams) t = readTeam(in, version);
  if (d.competition_type > 2)
    throw PacketError(v + "competitionType " + std::to_string(d.competition_type));
  if (d.game_phase > 3) throw PacketError(v + "gamePhase " + std::to_string(d.game_phase));
  if (d.state > 4) throw PacketError(v + "state " + std::to_string(d.state));
  if (set_play > 6) throw PacketError(v + "setPlay " + std::to_string(set_play));
  d.set_play = hsl::setPlayToSpl(set_play);
  return d;
}

std::vector<uint8_t> encodeControl(const ControlData& data, int version) {
  if (version == hsl::kVersion19 || version == hsl::kVersion20) return encodeHsl(data, version);
  const auto b = encode(data);
  return {b.begin(), b.end()};
}

ControlData decodeAnyControl(std::span<const uint8_t> bytes, int* version) {
  if (bytes.size() < 5) throw PacketError("control packet: " + std::to_string(bytes.size()) + " bytes");
  const int v = bytes[4];
  if (version) *version = v;
  return v == hsl::kVersion19 || v == hsl::kVersion20 ? decodeHsl(bytes) : decodeControl(bytes);
}

}  // namespace simsoccer::referee
