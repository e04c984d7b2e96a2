// The officials of a game: the automatic referee and the operator's part
// (starting each half as soon as it can, the shoot-out when a drawn game
// needs one, each shoot-out kick in turn). One order for every program:
// after the step, the referee judges, then the operator acts.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>

#include "simsoccer/referee/gamecontroller_link.hpp"
#include "simsoccer/referee/referee.hpp"
#include "simsoccer/sim/simulation.hpp"

namespace simsoccer::sim {

struct OfficialsConfig {
  // Teams by GameController team number; team index t plays in colour t.
  static OfficialsConfig forTeams(uint8_t team0, uint8_t team1);
  std::array<referee::TeamSetup, 2> teams;
  referee::RefereeConfig referee;
  int kick_off_team = 0;
  // A penalty-kick trial: one shoot-out kick from the start, team 0 kicking.
  bool penalty_kick_trial = false;
  uint64_t seed = 1;  // the shoot-out's coin toss
  // The operator's pauses before each half: Initial, then Standby (in
  // leagues that have it), then Ready; long enough for robots to see each
  // state in the 2 Hz GameController packets. initial_seconds is also the pause in a drawn
  // game's Finished before the shoot-out, in its Initial and in Finished between kicks.
  double initial_seconds = 1.0, standby_seconds = 1.0;
  // An external GameController runs the game: its packets are received on
  // this UDP port (0: any free one, for tests), the operator does nothing,
  // and the referee's own calls are reported only (referee::Referee::follow).
  std::optional<uint16_t> external_gc_port;
  // Where that GameController takes monitor requests (its true data;
  // referee::GameControllerListener).
  uint16_t external_gc_monitor_port = 3636;
  // With an external GameController the game is over this many seconds
  // after the GameController finished it and said nothing new (it may still
  // start a shoot-out).
  double external_end_wait = 60.0;
};

class GameOfficials : public Officials {
 public:
  GameOfficials(world::World& world, const referee::RuleBook& rules, const OfficialsConfig& config);

  void afterStep(std::vector<Event>& events) override;
  referee::ControlData controlData() const override { return referee_->game().packet(0); }
  int leftTeam() const override { return referee_->game().leftTeam(); }
  void teamMessages(int team, uint64_t total) override {
    referee_->game().setTeamMessagesSent(team, total);
  }

  referee::Referee& referee() { return *referee_; }
  // The external GameController's listener (null: the simulator runs the game).
  const referee::GameControllerListener* externalGameController() const { return listener_.get(); }
  const referee::Game& game() const { return referee_->game(); }
  // The game (and any shoot-out it needs) is decided; a penalty-kick trial:
  // its kick is over.
  bool over() const;

 private:
  void operatorPart();

  world::World& world_;
  OfficialsConfig config_;
  std::unique_ptr<referee::Referee> referee_;
  size_t events_seen_ = 0;
  std::array<int, 2> next_striker_{0, 0};
  std::optional<double> initial_since_, standby_since_;  // game time the state began
  std::optional<double> shootout_since_;  // the shoot-out's Finished or Initial began
  std::unique_ptr<referee::GameControllerListener> listener_;
  double last_change_ = 0.0;  // game time of the external GameController's last new state
};

// The team messages robots broadcast on a field network, as a GameController
// link counts them on the team ports, counted against each team's budget
// like the DDS agents' (a command source without robots). The link and the
// game must outlive it.
class FieldTeamMessages : public CommandSource {
 public:
  FieldTeamMessages(const referee::GameControllerLink& link, const referee::Game& game)
      : link_(link), game_(game) {}
  void observe(const Observation&) override {}
  void collect(uint64_t, CommandGate&, std::span<CommandSlot>) override {}
  uint64_t teamMessagesSent(int team) const override {
    return link_.teamMessages(game_.teamNumber(team));
  }

 private:
  const referee::GameControllerLink& link_;
  const referee::Game& game_;
};

}  // namespace simsoccer::sim
