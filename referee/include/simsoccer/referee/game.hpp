// The game as the SPL GameController runs it: states, halves, set plays,
// timers, scores and per-robot penalties, on simulated time, with every
// decision kept as an event. Rule parameters come from a rule book
// (configs/rules/*.yaml). This is the state machine; automatic refereeing
// from the world (goals, ball out, fouls) drives it through the commands.
//
// Teams are addressed by index: team 0 defends the -x goal in the first
// half (the goal on the GameController operator's left), team 1 the +x goal;
// they swap at half-time.
#pragma once

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/referee/gamecontroller.hpp"

namespace simsoccer::referee {

struct RuleBook {
  std::string name;
  std::string source_file;
  int players_per_team = 5;
  int halves = 2;
  double half_duration = 600, half_time_break = 600, half_time_to_initial = 300;
  bool clock_in_ready_and_set = true;
  double ready_duration = 45, ready_penalty_kick_duration = 30;
  double kick_off_ball_free = 10, set_play_duration = 30, penalty_kick_duration = 30;
  int mercy_goal_difference = 10;
  double game_stuck_duration = 30;
  int goal_area_max_robots = 3;
  // After a restart two robots of a team must play the ball before it scores (the SPL's 2025 rule).
  bool indirect_kick = true;
  // The HSL's restarts (rules/game.tex): a goal straight from a kick-off does not count (with
  // three or more of the kicking team's robots on the field two different robots must have
  // touched the ball, else its kicker outside the centre circle); a kick-in is indirect (another
  // robot, of either team, must touch the ball); a free kick straight into the kicker's own goal
  // is a corner kick. Each direct goal the rules refuse becomes a goal kick.
  bool kick_off_direct_goal = true;
  bool kick_in_indirect = false;
  bool free_kick_own_goal_corner = false;
  // Opponents keep this far from the ball at a free kick (m); the field's centre-circle radius
  // where free_kick_distance_centre_circle (HSL). At a goal kick, where
  // goal_kick_clears_penalty_area (HSL), they keep out of the kicking team's penalty area instead.
  double free_kick_distance = 0.75;
  bool free_kick_distance_centre_circle = false;
  bool goal_kick_clears_penalty_area = false;
  // A fallen robot is Inactive when down this long (s; the referee's stand-in for "no get-up
  // attempt started in time") or after this many failed get-ups (one more when disturbed).
  double fallen_time = 10;
  int get_up_attempts = 2;
  double team_timeout = 300, referee_timeout = 600;  // s
  int timeouts_per_team = 1;
  double penalty_base = 45, penalty_increment = 10;
  double illegal_position_in_set = 15, motion_in_set = 15;
  bool motion_in_set_in_place = true;  // SPL 2025; the HSL removes the robot
  bool shootout = true;
  int shootout_kicks = 3;
  double shootout_shot_duration = 30;
  bool sudden_death = true;
  int sudden_death_rounds = 3;  // then a coin decides
  int message_budget = 1200;    // team messages per team per game (GameController: messagesPerTeam)
  // The GameController whose packets the game goes out as: 18 (SPL, GameController3), 20 (HSL,
  // RoboCup 2026) or 19 (HSL, the German Open 2026); the HSL has no Standby state.
  int gc_version = 18;
  bool standby = true;
  uint8_t competition_type = 0;  // HSL: 0 SMALL, 1 MIDDLE, 2 LARGE (v18: 0 NORMAL)
};

// Reads and checks a rule book; throws engine::ConfigError (file, key, reason).
RuleBook loadRuleBook(const std::filesystem::path& file);

struct TeamSetup {
  uint8_t number = 0;  // GameController team number
  uint8_t field_player_colour = 0;
  uint8_t goalkeeper_colour = 0;
  uint8_t goalkeeper = 1;  // player number
};

// What a referee event is. eventName() gives the name logs and summaries use.
enum class EventType : uint8_t {
  State,       // the game state changed (detail: the new state and why)
  Half,        // a half began or ended
  GameOver,    // the game is decided (detail: how)
  Shootout,    // a penalty shoot-out began
  Shot,        // a shoot-out kick was set up
  ShotOver,    // a shoot-out kick ended (detail: its outcome)
  Goal,        // detail: the score after it
  SetPlay,     // a set play was awarded or is over
  Penalty,     // a robot was penalised (detail: the penalty)
  Unpenalise,  // a penalised robot may play again
  Timeout,     // a team or referee timeout
  DropBall,    // the ball was dropped
  Substitute,  // a substitution
  // The referee's own calls that are not state changes:
  Pushing,          // a robot pushed another (the penalty follows as Penalty)
  BallContact,      // a field player played the ball with an arm
  Placement,        // a robot was auto-placed at Set
  GoalDisallowed,   // the ball went in but the goal does not count
  IllegalPosition,  // a robot stood illegally at Set
  Inactive,         // a robot down too long, idle next to the ball, or its get-ups failed
  // An external GameController runs the game: what the automatic referee
  // would have called (detail: the call), reported only.
  Advisory,
};
// "state", "half", "game_over", "shootout", "shot", "shot_over", "goal",
// "set_play", "penalty", "unpenalise", "timeout", "drop_ball", "substitute", "pushing",
// "ball_contact", "placement", "goal_disallowed", "illegal_position", "inactive", "advisory".
const char* eventName(EventType t);

struct RefereeEvent {
  double time = 0.0;  // s of simulated time
  EventType type = EventType::State;
  int team = -1;      // team index, -1 none
  int player = 0;     // player number, 0 none
  std::string detail;
};

enum class Half { First, Second, PenaltyShootout };

// How a shoot-out kick ended, best first: the rules rank sudden-death kicks
// by these categories.
enum class ShotOutcome : uint8_t { Goal, Saved, Post, Wide, Other, NoKick };
const char* shotOutcomeName(ShotOutcome o);

class Game {
 public:
  // `kick_off_team`: the team index that kicks off the first half.
  Game(const RuleBook& rules, const std::array<TeamSetup, 2>& teams, int kick_off_team);

  // --- time (simulated) -------------------------------------------------------------
  // Runs the timers for dt seconds and makes the transitions the rules make
  // on their own (Ready -> Set after its maximum, the end of a kick-off or a
  // set play, the end of a half, half-time, penalty expiry).
  void advance(double dt);

  // --- commands (a user, a test or the automatic referee) -----------------------------
  void standby();       // Initial/Timeout -> Standby
  void ready();         // Initial/Standby/Timeout -> Ready (kick-off)
  void set();           // Ready -> Set
  void playing();       // Set -> Playing
  void goal(int team);  // `team` scored
  void ballFree();      // the kick-off or set play is over (the ball moved)
  void setPlay(gc::SetPlay play,
               int team);  // a free kick / kick-in / corner / goal kick for `team`
  void penalise(int team, int player, gc::Penalty penalty);
  void unpenalise(int team, int player);
  void timeout(std::optional<int> team);  // a team timeout, or a referee timeout (nullopt)
  void dropBall();  // restart without a kicking team (after a global game stuck)
  void substitute(int team, int player_out, int player_in);
  // The team messages `team` has sent so far (the GameController counts them on the team
  // port), called as the total grows: those sent while the game is in Standby, Ready, Set or
  // Playing outside the shoot-out count, and its packets' message budget is what is left.
  void setTeamMessagesSent(int team, uint64_t total);
  int messageBudget(int team) const;

  // --- penalty shoot-out (spl-rules.md section 6) ---------------------------------------
  // Starts the shoot-out: after a drawn game, or from Initial before any
  // kick-off as a stand-alone penalty-kick scenario (`kicks_per_team`
  // overrides the rule book's). `first_team` shoots first; `coin_seed` seeds
  // the coin that decides after the last sudden-death round.
  void startShootout(int first_team, std::optional<int> kicks_per_team = std::nullopt,
                     uint64_t coin_seed = 0);
  // The next kick (-> Set): the kicking team's striker and the other team's
  // keeper (0: none); every other robot becomes a substitute.
  void shootoutKick(int striker, int keeper);
  void shotKicked();  // the striker touched the ball (time-out: Other, not NoKick)
  void finishShot(ShotOutcome outcome);  // the kick ended without a goal (goals: goal())
  int shotsTaken(int team) const { return shots_[static_cast<size_t>(team)]; }
  const std::vector<ShotOutcome>& shotOutcomes(int team) const {
    return outcomes_[static_cast<size_t>(team)];
  }
  std::optional<int> winner() const { return winner_; }  // once the game (or shoot-out) is decided
  bool shootoutOpen() const { return phase_ == gc::GamePhase::PenaltyShoot && !game_over_; }
  int shootoutStriker() const { return striker_; }
  int shootoutKeeper() const { return keeper_; }
  bool shotKickedYet() const { return shot_kicked_; }  // this kick's striker touched the ball

  // --- state ----------------------------------------------------------------------------
  gc::State state() const { return state_; }
  gc::GamePhase phase() const { return phase_; }
  gc::SetPlay currentSetPlay() const { return set_play_; }
  // Set plays awarded so far: a new award of the same set play to the same team changes it.
  uint32_t setPlaysAwarded() const { return set_plays_awarded_; }
  Half half() const { return half_; }
  int kickingTeam() const { return kicking_team_; }  // -1 none
  int score(int team) const { return score_[static_cast<size_t>(team)]; }
  double secondsRemaining() const { return half_clock_; }  // of the half
  double secondaryTime() const { return secondary_; }      // 0 when none runs
  bool gameOver() const { return game_over_; }
  // Remaining penalty seconds (0: not penalised).
  double penaltyTime(int team, int player) const;
  gc::Penalty penalty(int team, int player) const;
  // Which team defends the -x goal now (the operator's left).
  int leftTeam() const { return sides_swapped_ ? 1 : 0; }
  int goalkeeper(int team) const { return teams_[static_cast<size_t>(team)].goalkeeper; }
  uint8_t teamNumber(int team) const { return teams_[static_cast<size_t>(team)].number; }
  const std::vector<RefereeEvent>& events() const { return events_; }
  double time() const { return time_; }
  const RuleBook& rules() const { return rules_; }

  // A referee decision that is not a state change (placement, ...).
  void recordEvent(EventType type, int team, int player, const std::string& detail) {
    log(type, team, player, detail);
  }

  // The GameController packet for this state (teams[0]: the left team).
  ControlData packet(uint8_t packet_number) const;

  // --- an external GameController runs the game ---------------------------------------
  // Takes the state, set play, kicking team, clocks, scores, goalkeepers and
  // penalties of an external GameController's packet, with an event for each
  // change (goals, penalties, states). Throws PacketError when the packet's
  // teams are not this game's.
  void follow(const ControlData& packet);
  // Simulated time passes between packets (the followed clocks stay as sent).
  void followTime(double dt) { time_ += dt; }

 private:
  struct Player {
    gc::Penalty penalty = gc::Penalty::None;
    double remaining = 0.0;
  };
  void enter(gc::State s, const std::string& why);
  void startKickOff(int team, const std::string& why);  // -> Ready, kick-off for `team`
  void endHalf();
  void endShot(ShotOutcome outcome, const std::string& why);
  void decideShootout();
  void log(EventType type, int team, int player, const std::string& detail);
  bool halfClockRuns() const;
  Player& player(int team, int number);
  const Player& player(int team, int number) const;

  RuleBook rules_;
  std::array<TeamSetup, 2> teams_;
  gc::State state_ = gc::State::Initial;
  gc::GamePhase phase_ = gc::GamePhase::Normal;
  gc::SetPlay set_play_ = gc::SetPlay::None;
  uint32_t set_plays_awarded_ = 0;
  Half half_ = Half::First;
  int first_half_kick_off_ = 0;
  int kicking_team_ = -1;
  bool kick_off_pending_ = true;  // kick-off set play when Playing starts
  bool break_timer_ = false;      // secondary_ is the half-time break's, run on into Initial
  bool half_started_ = false;     // the half's first kick-off has happened (clock runs)
  bool sides_swapped_ = false;
  bool game_over_ = false;
  std::array<int, 2> score_{};
  std::array<int, 2> incremental_{};  // incremental penalties so far, per team
  std::array<int, 2> timeouts_left_{1, 1};
  std::array<uint64_t, 2> messages_seen_{};     // the sources' totals at the last call
  std::array<uint64_t, 2> messages_counted_{};  // against the budget
  bool stopped_ = false;  // an external HSL GameController stopped play
  double half_clock_ = 0.0, secondary_ = 0.0, time_ = 0.0;
  // Shoot-out.
  int first_shooter_ = 0, shootout_kicks_ = 3, striker_ = 0, keeper_ = 0;
  bool shot_kicked_ = false;
  uint64_t coin_seed_ = 0;
  std::array<int, 2> shots_{};
  std::array<std::vector<ShotOutcome>, 2> outcomes_;
  std::optional<int> winner_;
  std::array<std::array<Player, gc::kMaxPlayers>, 2> players_{};
  std::vector<RefereeEvent> events_;
};

const char* stateName(gc::State s);
const char* setPlayName(gc::SetPlay p);

}  // namespace simsoccer::referee
