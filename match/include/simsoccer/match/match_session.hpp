// A game as the match runner plays it and the replay re-runs it: the match
// config, the world, the referee (with the operator's part: starting halves,
// the shoot-out) and the per-period bookkeeping that goes into the summary.
#pragma once

#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/lola/sensor_packet.hpp"
#include "simsoccer/referee/referee.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/match_log.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::match {

struct VideoSettings {
  bool enabled = true;
  double fps = 25.0;
  int width = 640, height = 360;
  engine::Vec3 position{0.0, -7.0, 5.0}, look_at{0.0, 0.0, 0.0};  // m, field frame
  double horizontal_fov = 1.1;                                    // rad
};

// A robot driven through LoLA (a team's robot binary) instead of a built-in agent.
struct LolaPlayer {
  int team_number = 0, player = 0;  // GameController team number, player number
};
// "1:3,2:1" (team number:player, comma separated); throws std::invalid_argument
// naming the entry that is not one.
std::vector<LolaPlayer> parseLolaPlayers(const std::string& list);

struct LolaSettings {
  std::vector<LolaPlayer> robots;
  size_t from_option = 0;  // the last ones came from the command line (--lola), not the file
  // Started once per LoLA robot with "{socket}" replaced by its socket path
  // (e.g. `simsoccer lola-run --socket {socket} -- ./team-binary`); empty:
  // the clients are started by hand.
  std::vector<std::string> client;
  double connect_timeout = 60.0;  // s the match waits for every LoLA client before it starts
  // Lockstep: s a match waits for a client that went away to connect again, once per
  // disconnection (lola::EndpointConfig::reconnect_timeout).
  double reconnect_timeout = 10.0;
  // With the scenario's cameras on: the k-th LoLA robot's images on TCP
  // ports image_port + 2k (top) and + 2k + 1 (bottom), as the Webots LoLA
  // controller's 10001/10002 for one robot.
  uint16_t image_port = 10001;
  // The field's network for the binaries (needs root): GameController
  // packets, status and team messages over UDP as on a field.
  bool network = false;
  // RobotConfig strings per robot ("T:P") where not lola::defaultIdentity's.
  std::map<std::string, lola::RobotIdentity> identities;
  // Battery[3] carries the LoLA cycle counter, as under the Webots LoLA controller
  // (lola::RobotSocket::tick_in_battery); false: the battery's temperature.
  bool tick_in_battery = true;
};

struct MatchConfig {
  std::string file, name;
  std::filesystem::path scenario, rules, agent_config;
  // The agents' motions and gaits: agents.motions, else the folder `motions` beside the match's
  // file where there is one (a copied configs tree plays its own gaits), else the agents' default.
  std::filesystem::path agent_motions;
  std::optional<double> half_duration, half_time_break;
  std::array<int, 2> team_numbers{1, 2};
  std::string role = "auto";
  bool get_up = true;
  int restart_limit = 3;
  double message_delay = 0.0, message_loss = 0.0;
  double command_timeout = 0.5;  // s of wall time a lockstep period waits for commands
  double set_duration = 5.0;     // s in Set before the referee whistles
  VideoSettings video;
  uint64_t seed = 1;
  int penalty_kicks = 0;  // > 0: a penalty-kick scenario (simsoccer penalty)
  // With LoLA robots the control period is LoLA's 12 ms (and the physics
  // step 3 ms when the scenario's does not divide it).
  LolaSettings lola;
  // An external GameController runs the game (its packets on this UDP port,
  // normally 3838); the match then runs in real time.
  std::optional<uint16_t> external_gc_port;
  std::string hash;       // of the config and scenario files' bytes
};
// Reads a match or penalty config; throws engine::ConfigError (file, key, reason).
MatchConfig loadMatchConfig(const std::filesystem::path& file);
// Players numbered beyond the rule book's team size are substitutes (penalised, as GameController
// 3 starts a game): a scenario with more robots in a team is refused, engine::ConfigError naming
// the rule book's players_per_team.
void checkTeamSizes(const referee::RuleBook& rules, const world::Scenario& scenario);

// A robot going down (not a keeper's dive): when, where, and how near the
// nearest other robot and the ball were (a push, a kick, or on its own).
struct FallRecord {
  double time = 0.0;                    // s of simulated time
  double x = 0.0, y = 0.0;              // torso, field frame, m
  std::optional<double> nearest_robot;  // m, torso to torso (none: no other robot)
  double ball = 0.0;                    // m, torso to ball
  // s until it stood again, for 1 s, within 1 m of where it fell (its
  // get-up); none: it did not before the match ended, or the referee moved
  // it (a penalty's placement).
  std::optional<double> up_after;
};

// Touches of the ball as a spectator counts them: a robot's contact with the ball after 0.1 s
// without one of its own, or after another robot's. Fed the world's last touch after every
// period; gives the touch that begins a new one.
class BallTouchCounter {
 public:
  explicit BallTouchCounter(double physics_dt);
  std::optional<world::BallTouch> next(const std::optional<world::BallTouch>& last);
  // The last contact seen (the world's last touch as of the last call).
  const std::optional<world::BallTouch>& last() const { return seen_; }

 private:
  uint64_t gap_steps_;
  std::optional<world::BallTouch> seen_;
};

struct RobotRecord {
  int team = 0, number = 0;
  int touches = 0;  // of the ball (BallTouchCounter)
  std::vector<FallRecord> falls;
  int dives = 0;          // the shoot-out keeper going down once the shot is kicked: not a fall
  double distance = 0.0;  // m walked (torso, teleports left out)
  bool standing = true;
  bool down_after_fall = false;  // lying after the last of `falls` (not a dive)
  double standing_since = 0.0;   // s, the time it last stood up
  engine::Vec3 last{0, 0, 0};
};

// The world, its officials (referee and operator) and the match records
// (falls, distance, possession, goals), which it keeps as a recorder of the
// simulation's period.
class MatchSession : public sim::Recorder {
 public:
  // `seed` overrides the config's. The world is built from the scenario with
  // that seed; the rule book's half duration and break as the config says.
  MatchSession(const MatchConfig& config, uint64_t seed, int solver_threads = 0);

  world::World& world() { return *world_; }
  const world::World& world() const { return *world_; }
  sim::GameOfficials& officials() { return *officials_; }
  const referee::Game& game() const { return officials_->game(); }
  const MatchConfig& config() const { return config_; }
  // Makes this session's officials and records part of `sim`'s period.
  void attach(sim::Simulation& sim);

  // Stage record: falls, distance, possession, goals (with their scorer).
  void record(const sim::PeriodRecord& p) override;
  bool over() const { return officials_->over(); }

  const std::vector<RobotRecord>& robots() const { return records_; }
  std::array<double, 2> possession() const;  // share of the time each team had the ball
  struct Goal {
    double time;
    // scorer: player number of the robot the goal is the work of, of either team (0: unknown);
    // own_goal: that robot was the other team's. As football counts goals, a shot that
    // a defender (or more) touched on its way in is the shooter's, not an own goal, if it
    // was going in before the first of them touched it (rolling over the goal line between
    // the posts before stopping) and went in within 2 s of that touch; deflected_by: then the
    // last of them (0: none). The referee judges the rules (a goal straight from an indirect
    // restart, the HSL's own goal from a free kick) by the last touch alone.
    int team, scorer;
    bool own_goal;
    int deflected_by = 0;
  };
  const std::vector<Goal>& goals() const { return goals_; }
  referee::ControlData controlData() const { return officials_->controlData(); }
  // The robots driven through LoLA, in the order of config().lola.robots.
  const std::vector<world::RobotId>& lolaRobots() const { return lola_robots_; }

 private:
  MatchConfig config_;
  std::unique_ptr<world::World> world_;
  std::unique_ptr<sim::GameOfficials> officials_;
  std::vector<RobotRecord> records_;
  // The shoot-out keeper of the last kicked shot (record index), until it goes
  // down (a dive) or the next shot is kicked: a goal ends the shot, and the
  // next kick is set up, before the diving keeper reaches the ground.
  std::optional<size_t> diving_keeper_;
  std::array<double, 2> possession_{};
  std::vector<Goal> goals_;
  // Ball touches seen at the end of each period (the last toucher: touches_->last()), who
  // touched the ball before the other team's robots did, and where it was heading then (a
  // goal's side, 0 none).
  std::optional<BallTouchCounter> touches_;  // made with the world (its physics step)
  std::optional<world::RobotId> before_other_team_;
  int heading_for_goal_ = 0;
  double other_team_since_ = 0.0;  // s: the other team's first touch
  // A shot in off a defender goes in within this many seconds of the defender's first touch
  // (in the K1 games traced, 0.2-1.5 s): later, the defending team had the ball meanwhile
  // (a save, then a clearance of its own into its goal) and the goal is its own.
  static constexpr double kDeflectedShotSeconds = 2.0;
  engine::RigidBodyState ball_before_;  // at the end of the period before
  std::vector<world::RobotId> lola_robots_;
};

}  // namespace simsoccer::match
