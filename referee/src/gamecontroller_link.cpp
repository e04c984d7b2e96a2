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
    p.receiver = std::make_unique<UdpReceiver>(
        static_cast<uint16_t>(10000 + p.team_number),
        config_.team_message_device.empty() ? config_.team_message_bind : std::string("0.0.0.0"),
        config_.team_message_device);
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

GameControllerListener::GameControllerListener(uint16_t port, const std::string& bind,
                                               uint16_t monitor_port)
    : receiver_(std::make_unique<UdpReceiver>(port, bind)), monitor_port_(monitor_port) {}

std::optional<ControlData> GameControllerListener::poll() {
  using Clock = std::chrono::steady_clock;
  constexpr auto kFresh = std::chrono::seconds(2);
  std::optional<ControlData> robots, truth;
  std::array<uint8_t, 512> buffer{};
  std::string source;
  for (size_t n; (n = receiver_->receive(buffer, 0.0, &source)) > 0;) {
    try {
      const ControlData d = decodeAnyControl(std::span<const uint8_t>(buffer.data(), n));
      ++accepted_;
      if (d.true_data) {
        truth = d;
        ++true_data_;
        last_true_ = Clock::now();
      } else {
        robots = d;
        if (source != gc_address_) monitor_sender_.reset();  // (another GameController host)
        gc_address_ = source;
      }
    } catch (const PacketError& e) {
      ++rejected_;
      last_error_ = e.what();
    }
  }
  const auto now = Clock::now();
  const bool fresh = true_data_ > 0 && now - last_true_ < kFresh;
  if (!fresh && !gc_address_.empty() && monitor_port_ != 0 && now - last_request_ >= kFresh) {
    try {
      if (!monitor_sender_)
        monitor_sender_ = std::make_unique<UdpSender>(gc_address_, monitor_port_);
      static constexpr std::array<uint8_t, 5> kRequest{'R', 'G', 'T', 'r', 0};
      monitor_sender_->send(kRequest);
      ++monitor_requests_;
    } catch (const std::runtime_error& e) {
      last_error_ = e.what();
    }
    last_request_ = now;
  }
  if (truth) return truth;
  return fresh ? std::nullopt : robots;
}

}  // namespace simsoccer::referee
