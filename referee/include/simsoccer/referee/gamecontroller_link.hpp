// The simulator as a GameController on the network: the referee's game
// state broadcast as RoboCupGameControlData (the rule book's version: 18,
// GameController3; 19, the HSL's) every 0.5 s of simulated time to port
// 3838 (0.2 s while play is stopped, as the HSL's), and
// RoboCupGameControlReturnData received on port 3939, so robot software
// written against the real GameController runs against the simulator.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "simsoccer/referee/game.hpp"
#include "simsoccer/referee/gamecontroller.hpp"

namespace simsoccer::referee {

struct GameControllerLinkConfig {
  std::string address = "255.255.255.255";  // where control packets go (tests: 127.0.0.1)
  uint16_t control_port = 3838;
  uint16_t return_port = 3939;  // 0: any free port (tests)
  std::string return_bind = "0.0.0.0";
  double period = 0.5;  // s of simulated time between control packets (GC3: 500 ms)
  // Count the playing teams' messages, as the GameController does, on their
  // team ports (10000 + team number) at this address (the field's broadcast
  // address; empty: not counted).
  std::string team_message_bind;
  // With it, on any address of this interface (the field network's bridge): the subnet's
  // broadcast and the limited one (255.255.255.255, which some teams send to and which a
  // socket bound to the subnet's broadcast address never gets). GameController3 listens on any
  // address.
  std::string team_message_device;
};

class GameControllerLink {
 public:
  explicit GameControllerLink(const GameControllerLinkConfig& config);  // throws on socket errors

  // Once per control period: sends the game's packet when `period` of
  // simulated time has passed since the last one (the first at once), and
  // takes in the return packets waiting. Never blocks and never throws for
  // what arrives: malformed return packets are counted and dropped.
  void update(const Game& game);

  uint16_t returnPort() const;
  uint64_t packetsSent() const { return sent_; }
  uint64_t returnsAccepted() const { return accepted_; }
  uint64_t returnsRejected() const { return rejected_; }
  const std::string& lastReturnError() const { return last_error_; }
  // The latest valid return packet from (team number, player number).
  std::optional<ReturnData> lastReturn(uint8_t team_number, uint8_t player) const;
  // Team messages counted on team `team_number`'s port so far.
  uint64_t teamMessages(uint8_t team_number) const;

 private:
  void receiveReturns(const Game& game);
  void bindTeamPorts(const Game& game);  // once, at the first update
  void countTeamMessages(const Game& game);
  struct TeamPort {
    uint8_t team_number = 0;
    std::unique_ptr<UdpReceiver> receiver;
    uint64_t messages = 0;
  };
  std::vector<TeamPort> team_ports_;

  GameControllerLinkConfig config_;
  std::unique_ptr<UdpSender> sender_;
  std::unique_ptr<UdpReceiver> receiver_;
  double next_send_ = 0.0;
  uint64_t sent_ = 0, accepted_ = 0, rejected_ = 0;  // packet number: sent_ mod 256
  std::string last_error_;
  std::map<std::pair<uint8_t, uint8_t>, ReturnData> returns_;  // ordered: deterministic iteration
};

// An external GameController's packets (v18, v19 or v20) received on its port
// (3838, shared with robot software on the same host: SO_REUSEADDR, and the
// GameController broadcasts). The simulator then does not bind 3939, so a
// GameController on the same host can. Malformed packets are counted and
// dropped; never blocks.
//
// The simulated world follows the game as it is, not as the robots are told it: the listener
// asks the GameController for its true data as a monitor does (`RGTr` to `monitor_port`, 3636,
// every 2 s until `RGTD` packets come to this port) and prefers them while they come. The
// robots' packets hide the kicking side of free kicks and penalty kicks in the Champions Cup
// (kickingTeam 255) and show Set up to 10 s after the whistle; true data does neither. A host
// that sent status packets gets no monitor service (GameController3): then the robots' packets
// are followed, and a penalty kick whose side is hidden leaves the ball where it is.
class GameControllerListener {
 public:
  explicit GameControllerListener(uint16_t port = 3838, const std::string& bind = "0.0.0.0",
                                  uint16_t monitor_port = 3636);
  uint16_t port() const { return receiver_->port(); }
  // The newest valid packet to follow received since the last call, if any: true data while it
  // comes (for 2 s after the last), else the robots' packets.
  std::optional<ControlData> poll();
  uint64_t accepted() const { return accepted_; }
  uint64_t rejected() const { return rejected_; }
  uint64_t trueData() const { return true_data_; }                // RGTD packets received
  uint64_t monitorRequests() const { return monitor_requests_; }  // RGTr sent
  const std::string& lastError() const { return last_error_; }

 private:
  std::unique_ptr<UdpReceiver> receiver_;
  uint16_t monitor_port_;
  std::string gc_address_;  // where the robots' packets come from
  std::unique_ptr<UdpSender> monitor_sender_;
  std::chrono::steady_clock::time_point last_true_{}, last_request_{};
  uint64_t accepted_ = 0, rejected_ = 0, true_data_ = 0, monitor_requests_ = 0;
  std::string last_error_;
};

}  // namespace simsoccer::referee
