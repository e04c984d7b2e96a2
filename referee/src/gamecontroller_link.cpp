#include "simsoccer/referee/gamecontroller_link.hpp"

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
  const ControlData current = game.packet(packet_number_);
  if (!sent_any_ || game.time() >= next_send_ - 1e-9) {
    sender_->send(encode(current));
    ++packet_number_;  // u8: wraps at 256 as the GameController's
    ++sent_;
    next_send_ = (sent_any_ ? next_send_ : game.time()) + config_.period;
    sent_any_ = true;
  }
  receiveReturns(current);
}

void GameControllerLink::receiveReturns(const ControlData& current) {
  std::array<uint8_t, 512> buffer{};  // larger than any packet: an oversized one shows its size
  for (size_t n; (n = receiver_->receive(buffer, 0.0)) > 0;) {
    try {
      const ReturnData r = decodeReturn(std::span<const uint8_t>(buffer.data(), n));
      // As GC3: only the playing teams' robots count.
      if (r.team_num != current.teams[0].team_number && r.team_num != current.teams[1].team_number)
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

}  // namespace simsoccer::referee
