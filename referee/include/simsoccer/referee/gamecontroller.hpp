// The SPL GameController wire format, byte-exact: RoboCupGameControlData
// version 18 ("RGme", 118 bytes, GameController -> robots, UDP broadcast to
// port 3838 at 2 Hz) and RoboCupGameControlReturnData version 4 ("RGrt",
// 32 bytes, robot -> GameController, UDP unicast to port 3939). Little-endian,
// serialised field by field (docs/reference.md, GameController packets).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "simsoccer/protocol/gamecontroller.hpp"

namespace simsoccer::referee {

// The GameController's enums and constants are the protocol's (shared with
// the agents).
namespace gc = protocol::gc;

struct RobotInfo {
  uint8_t penalty = 0;                // gc::Penalty
  uint8_t secs_till_unpenalised = 0;  // rounded up, clamped to 0..255
  uint8_t warnings = 0;               // HSL v19 only
  uint8_t cautions = 0;               // HSL v19 and v20
  bool operator==(const RobotInfo&) const = default;
};

struct TeamInfo {
  uint8_t team_number = 0;
  uint8_t field_player_colour = 0;
  uint8_t goalkeeper_colour = 0;
  uint8_t goalkeeper = 1;  // player number
  uint8_t score = 0;
  uint8_t penalty_shot = 0;   // shoot-out: shots started; otherwise the fallback-mode flag
  uint16_t single_shots = 0;  // bit i: shoot-out shot i + 1 scored
  uint16_t message_budget = 0;
  std::array<RobotInfo, gc::kMaxPlayers> players{};  // entry i: player number i + 1
  bool operator==(const TeamInfo&) const = default;
};

// RoboCupGameControlData, in the SPL's v18 codes (the simulator's and the
// agents' vocabulary, also when the game runs under HSL rules: the HSL
// functions below map the codes on the wire).
struct ControlData {
  bool true_data = false;  // "RGTD" (to monitors) instead of "RGme"
  uint8_t packet_number = 0;
  uint8_t players_per_team = 5;
  uint8_t competition_phase = 0;
  uint8_t competition_type = 0;  // v18: 0 NORMAL, 1 MOST_PASSES; HSL: 0 SMALL, 1 MIDDLE, 2 LARGE
  uint8_t stopped = 0;           // HSL (v19, v20) only: play is stopped
  uint8_t game_phase = 0;        // gc::GamePhase
  uint8_t state = 0;       // gc::State
  uint8_t set_play = 0;    // gc::SetPlay
  uint8_t first_half = 1;
  uint8_t kicking_team = gc::kKickingTeamNone;  // a team number, 255 = none
  int16_t secs_remaining = 0;
  int16_t secondary_time = 0;
  std::array<TeamInfo, 2> teams{};  // teams[0]: the team on the operator's left
  bool operator==(const ControlData&) const = default;
};

// RoboCupGameControlReturnData v4.
struct ReturnData {
  uint8_t player_num = 1;
  uint8_t team_num = 0;
  uint8_t fallen = 0;
  std::array<float, 3> pose{};  // x, y (mm), theta (rad), team-relative field frame
  float ball_age = -1.0f;       // s since the ball was last seen, -1 never
  std::array<float, 2> ball{};  // mm, relative to the robot
  bool operator==(const ReturnData&) const = default;
};

constexpr size_t kRobotInfoSize = 2;
constexpr size_t kTeamInfoSize = 6 + 2 + 2 + gc::kMaxPlayers * kRobotInfoSize;
constexpr size_t kControlHeaderSize = 4 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 2 + 2;
constexpr size_t kControlSize = kControlHeaderSize + 2 * kTeamInfoSize;
constexpr size_t kReturnSize = 4 + 1 + 1 + 1 + 1 + 3 * 4 + 4 + 2 * 4;
static_assert(kTeamInfoSize == 50, "TeamInfo is 50 bytes on the wire");
static_assert(kControlHeaderSize == 18, "the control packet's header part is 18 bytes");
static_assert(kControlSize == 118, "RoboCupGameControlData v18 is 118 bytes");
static_assert(kReturnSize == 32, "RoboCupGameControlReturnData v4 is 32 bytes");

// A malformed packet: the reason names what is wrong.
class PacketError : public std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::array<uint8_t, kControlSize> encode(const ControlData& data);
ControlData decodeControl(std::span<const uint8_t> bytes);  // throws PacketError

// The HSL GameController's RoboCupGameControlData (RoboCup-HumanoidSoccerLeague/GameController,
// game_controller_msgs/headers/RoboCupGameControlData.h and its Wireshark dissector): the same
// header part as v18 with competitionPhase replaced by competitionType (SMALL/MIDDLE/LARGE) and
// competitionType's byte by `stopped`, no Standby, the HSL's set-play and penalty codes (mapped
// from and to the SPL's here; docs/referee.md).
// - v20 (GameController v7.0.0, RoboCup 2026; 158 bytes): RobotInfo of 3 bytes (penalty,
//   secsTillUnpenalised, cautions), penalties 1..13 with Motion in Stop and Cautioned.
// - v19 (GameController v6.0, the German Open 2026; 198 bytes): RobotInfo of 4 bytes (penalty,
//   secsTillUnpenalised, warnings, cautions), penalties 1..11.
namespace hsl {
constexpr uint8_t kVersion19 = 19;
constexpr uint8_t kVersion20 = 20;
constexpr uint8_t kControlVersion = kVersion20;  // the current one
constexpr size_t robotInfoSize(int version) {
  return version == kVersion19 ? 4 : 3;
}
constexpr size_t teamInfoSize(int version) {
  return 6 + 2 + 2 + gc::kMaxPlayers * robotInfoSize(version);
}
constexpr size_t controlSize(int version) {
  return kControlHeaderSize + 2 * teamInfoSize(version);
}
static_assert(teamInfoSize(kVersion19) == 90 && controlSize(kVersion19) == 198,
              "RoboCupGameControlData v19 is 198 bytes");
static_assert(teamInfoSize(kVersion20) == 70 && controlSize(kVersion20) == 158,
              "RoboCupGameControlData v20 is 158 bytes");
uint8_t setPlayFromSpl(uint8_t spl);
uint8_t setPlayToSpl(uint8_t hsl);
// `version` 19 or 20: their penalty codes differ.
uint8_t penaltyFromSpl(uint8_t spl, int version);
uint8_t penaltyToSpl(uint8_t hsl, int version);  // throws PacketError for a code out of range
}  // namespace hsl
// The packet in HSL version 19 or 20.
std::vector<uint8_t> encodeHsl(const ControlData& data, int version = hsl::kControlVersion);
ControlData decodeHsl(std::span<const uint8_t> bytes);  // v19 or v20; throws PacketError
// The packet as the given GameController version sends it (18, 19 or 20).
std::vector<uint8_t> encodeControl(const ControlData& data, int version);
// A v18, v19 or v20 packet, told apart by its version byte (and checked for its size).
ControlData decodeAnyControl(std::span<const uint8_t> bytes, int* version = nullptr);
std::array<uint8_t, kReturnSize> encode(const ReturnData& data);
ReturnData decodeReturn(std::span<const uint8_t> bytes);  // throws PacketError (GC3's checks)

// UDP, IPv4. A sender for control packets (broadcast allowed) and a
// non-blocking receiver; malformed packets are counted and dropped.
class UdpSender {
 public:
  UdpSender(const std::string& address, uint16_t port);  // throws std::runtime_error
  ~UdpSender();
  UdpSender(const UdpSender&) = delete;
  UdpSender& operator=(const UdpSender&) = delete;
  void send(std::span<const uint8_t> bytes);

 private:
  int fd_ = -1;
  std::array<uint8_t, 16> address_{};  // sockaddr_in
};

class UdpReceiver {
 public:
  // `device`: only datagrams that arrive on this network interface (SO_BINDTODEVICE; before
  // Linux 5.7 it needs CAP_NET_RAW), with bind_address 0.0.0.0 both the subnet's and the
  // limited broadcast.
  explicit UdpReceiver(uint16_t port, const std::string& bind_address = "0.0.0.0",
                       const std::string& device = "");
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;
  uint16_t port() const { return port_; }  // the bound port (useful with port 0)
  // Waits up to `timeout_seconds` for one datagram; returns its size, 0 on timeout. `source`:
  // the sender's IPv4 address in dotted form.
  size_t receive(std::span<uint8_t> buffer, double timeout_seconds, std::string* source = nullptr);

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
};

}  // namespace simsoccer::referee
