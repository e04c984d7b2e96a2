#include "simsoccer/referee/gamecontroller_link.hpp"

#include <algorithm>
#include <array>

namespace simsoccer::referee {

GameControllerLink::GameControllerLink(const GameControllerLinkConfig& config)
    : config_(config),
      sender_(std::make_unique<UdpSender>(config.address, config.control_port)),
      receiver_(std::make_unique<UdpReceiver>(config.return_port, config.return_bind)) {
  if (!(config.period > 0.0))
    throw std::invalid_argument("GameController link: period must be > 0");
}

uint16_t GameControllerLink::returnPort() const {
  return receiver_->port();
}

void GameControllerLink::update(const Game& game) {
  // The team ports are bound before the first packet goes out: a robot may
  // answer it with a team message at once.
  bindTeamPorts(game);
  if (sent_ == 0 || game.time() >= next_send_ - 1e-9) {
    // The packet number is a u8 that wraps at 256, as the GameController's.
    const ControlData d = game.packet(static_cast<uint8_t>(sent_));
    sender_->send(encodeControl(d, game.rules().gc_version));
    // The HSL GameController sends at 5 Hz while play is stopped.
    const double period = d.stopped ? std::min(config_.period, 0.2) : config_.period;
    next_send_ = (sent_ == 0 ? game.time() : next_send_) + period;
    ++sent_;
  }
  receiveReturns(game);
  countTeamMessages(game);
}

void GameControllerLink::bindTeamPorts(const Game& game) {
  if (config_.team_message_bind.empty() || !team_ports_.empty()) return;
  for (int t = 0; t < 2; ++t) {
    TeamPort p;
    p.team_number = game.teamNumber(t);
    p.receiver = std::make_unique<UdpReceiver>(static_cast<uint16_t>(10000 + p.team_number),
                                               config_.team_message_bind);
    team_ports_.push_back(std::move(p));
  }
}

void GameControllerLink::countTeamMessages(const Game& game) {
  bindTeamPorts(game);
  std::array<uint8_t, 1024> buffer{};
  for (TeamPort& p : team_ports_)
    while (p.receiver->receive(buffer, 0.0) > 0) ++p.messages;
}

uint64_t GameControllerLink::teamMessages(uint8_t team_number) const {
  for (const TeamPort& p : team_ports_)
    if (p.team_number == team_number) return p.messages;
  return 0;
}

void GameControllerLink::receiveReturns(const Game& game) {
  std::array<uint8_t, 512> buffer{};  // larger than any packet: an oversized one shows its size
  for (size_t n; (n = receiver_->receive(buffer, 0.0)) > 0;) {
    try {
      const ReturnData r = decodeReturn(std::span<const uint8_t>(buffer.data(), n));
      // As GC3: only the playing teams' robots count.
      if (r.team_num != game.teamNumber(0) && r.team_num != game.teamNumber(1))
        throw PacketError("return packet from team " + std::to_string(r.team_num) +
                          ", which is not playing");
      returns_[{r.team_num, r.player_num}] = r;
      ++accepted_;
    } catch (const PacketError& e) {
      ++rejected_;
      last_error_ = e.what();
    }
  }
}

std::optional<ReturnData> GameControllerLink::lastReturn(uint8_t team_number,
                                                         uint8_t player) const {
  const auto it = returns_.find({team_number, player});
  if (it == returns_.end()) return std::nullopt;
  return it->second;
}

GameControllerListener::GameControllerListener(uint16_t port, const std::string& bind)
    : receiver_(std::make_unique<UdpReceiver>(port, bind)) {}

std::optional<ControlData> GameControllerListener::poll() {
  std::optional<ControlData> latest;
  std::array<uint8_t, 512> buffer{};
  for (size_t n; (n = receiver_->receive(buffer, 0.0)) > 0;) {
    try {
      latest = decodeAnyControl(std::span<const uint8_t>(buffer.data(), n));
      ++accepted_;
    } catch (const PacketError& e) {
      ++rejected_;
      last_error_ = e.what();
    }
  }
  return latest;
}

}  // namespace simsoccer::referee
