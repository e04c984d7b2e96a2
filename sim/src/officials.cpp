#include "simsoccer/sim/officials.hpp"

namespace simsoccer::sim {

OfficialsConfig OfficialsConfig::forTeams(uint8_t team0, uint8_t team1) {
  OfficialsConfig c;
  c.teams[0].number = team0;
  c.teams[1].number = team1;
  // Four different colours (a GameController refuses a clash): team 0 blue
  // with a yellow goalkeeper, team 1 red with a black one.
  using protocol::gc::Colour;
  c.teams[0].field_player_colour = static_cast<uint8_t>(Colour::Blue);
  c.teams[0].goalkeeper_colour = static_cast<uint8_t>(Colour::Yellow);
  c.teams[1].field_player_colour = static_cast<uint8_t>(Colour::Red);
  c.teams[1].goalkeeper_colour = static_cast<uint8_t>(Colour::Black);
  return c;
}

GameOfficials::GameOfficials(world::World& world, const referee::RuleBook& rules,
                             const OfficialsConfig& config)
    : world_(world), config_(config) {
  referee_ = std::make_unique<referee::Referee>(world, rules, config.teams, config.kick_off_team,
                                                config.referee);
  if (config.external_gc_port) {
    listener_ = std::make_unique<referee::GameControllerListener>(
        *config.external_gc_port, "0.0.0.0", config.external_gc_monitor_port);
    return;  // the external GameController's operator starts the game
  }
  if (config.penalty_kick_trial) referee_->game().startShootout(0, 1, config.seed);
  operatorPart();
}

void GameOfficials::operatorPart() {
  referee::Game& g = referee_->game();
  using referee::gc::State;
  // Each half starts after the operator's pauses: Initial, Standby (not in
  // the HSL, whose GameController has none), then Ready.
  const auto waited = [&](std::optional<double>& since, double seconds) {
    if (!since) since = g.time();
    if (g.time() - *since < seconds - 1e-9) return false;
    since.reset();
    return true;
  };
  if (g.state() == State::Initial && g.phase() == referee::gc::GamePhase::Normal && !g.gameOver()) {
    if (waited(initial_since_, config_.initial_seconds)) {
      if (g.rules().standby)
        g.standby();
      else
        g.ready();
    }
  } else {
    initial_since_.reset();
  }
  if (g.state() == State::Standby && g.phase() == referee::gc::GamePhase::Normal) {
    if (waited(standby_since_, config_.standby_seconds)) g.ready();
  } else {
    standby_since_.reset();
  }
  // A drawn game goes to the shoot-out when the rule book calls for it, after the operator's
  // pause in Finished; each kick after one in Initial (the shoot-out's start) or Finished (the
  // last kick's end), so that robots see those states as GameController3 sends them (they
  // went from Playing straight to the next kick's Set). A penalty-kick trial has no pauses.
  const bool pause = !config_.penalty_kick_trial;
  const bool drawn = g.gameOver() && !g.winner() && g.phase() == referee::gc::GamePhase::Normal &&
                     g.rules().shootout && !config_.penalty_kick_trial;
  const auto between_kicks = [&] {
    return g.shootoutOpen() && (g.state() == State::Initial || g.state() == State::Finished);
  };
  if (!drawn && !between_kicks()) shootout_since_.reset();
  if (drawn && waited(shootout_since_, config_.initial_seconds))
    g.startShootout(0, std::nullopt, world_.scenario().seed);
  // The next shoot-out kick: the kicking team's field players in turn against
  // the other team's goalkeeper.
  if (between_kicks() && (!pause || waited(shootout_since_, config_.initial_seconds))) {
    const int team = g.shotsTaken(0) <= g.shotsTaken(1) ? 0 : 1;
    std::vector<int> strikers;
    for (world::RobotId r = 0; r < world_.robotCount(); ++r)
      if (world_.robot(r).team == team && world_.robot(r).number != g.goalkeeper(team))
        strikers.push_back(world_.robot(r).number);
    if (strikers.empty()) strikers.push_back(g.goalkeeper(team));
    const int striker =
        strikers[static_cast<size_t>(next_striker_[static_cast<size_t>(team)]++) %
                 strikers.size()];
    int keeper = g.goalkeeper(1 - team);
    if (!referee_->robot(1 - team, keeper)) keeper = 0;
    referee_->startShootoutKick(striker, keeper);
  }
}

void GameOfficials::afterStep(std::vector<Event>& events) {
  if (listener_) {
    if (const auto packet = listener_->poll()) {
      const referee::ControlData before = referee_->game().packet(0);
      try {
        referee_->follow(*packet);
      } catch (const referee::PacketError&) {
        // Another game's GameController on the network: not ours to follow.
      }
      const referee::ControlData after = referee_->game().packet(0);
      if (after.state != before.state || after.game_phase != before.game_phase ||
          after.first_half != before.first_half)
        last_change_ = referee_->game().time();
    }
    referee_->update();
  } else {
    referee_->update();
    operatorPart();
  }
  const auto& all = referee_->game().events();
  for (; events_seen_ < all.size(); ++events_seen_) events.push_back(all[events_seen_]);
}

bool GameOfficials::over() const {
  const referee::Game& g = referee_->game();
  if (listener_)
    return g.gameOver() && g.time() - last_change_ >= config_.external_end_wait - 1e-9;
  if (config_.penalty_kick_trial) return !g.shotOutcomes(0).empty() || g.gameOver();
  return g.gameOver() && !g.shootoutOpen() &&
         !(g.phase() == referee::gc::GamePhase::Normal && !g.winner() && g.rules().shootout);
}

}  // namespace simsoccer::sim
