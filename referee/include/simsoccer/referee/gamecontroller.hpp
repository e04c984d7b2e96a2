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

#include "simsoccer/protocol/gamecontroller.hpp"

namespace simsoccer::referee {

// The GameController's enums and constants are the protocol's (shared with
// the agents).
namespace gc = protocol::gc;

struct RobotInfo {
  uint8_t penalty = 0;                // gc::Penalty
  uint8_t secs_till_unpenalised = 0;  // rounded up, clamped to 0..255
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

// RoboCupGameControlData v18.
struct ControlData {
  bool true_data = false;  // "RGTD" (to monitors) instead of "RGme"
  uint8_t packet_number = 0;
  uint8_t players_per_team = 5;
  uint8_t competition_phase = 0;
  uint8_t competition_type = 0;
  uint8_t game_phase = 0;  // gc::GamePhase
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
  explicit UdpReceiver(uint16_t port, const std::string& bind_address = "0.0.0.0");
  ~UdpReceiver();
  UdpReceiver(const UdpReceiver&) = delete;
  UdpReceiver& operator=(const UdpReceiver&) = delete;
  uint16_t port() const { return port_; }  // the bound port (useful with port 0)
  // Waits up to `timeout_seconds` for one datagram; returns its size, 0 on timeout.
  size_t receive(std::span<uint8_t> buffer, double timeout_seconds);

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
};

}  // namespace simsoccer::referee
