// The automatic referee: watches the world once per control period and
// drives the Game the way the SPL's human referees and GameController
// operator do (spl-rules.md sections 4-5): goals, ball out with the right
// restart and ball placement, the end of kick-offs and set plays, automatic
// penalties, removal of penalised robots and their re-entry.
#pragma once

#include <array>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/referee/game.hpp"
#include "simsoccer/world/world.hpp"

namespace simsoccer::referee {

struct RefereeConfig {
  bool auto_placement = false;    // at Set, move illegally placed robots instead of penalising
  double set_duration = 5.0;      // s in Set before the referee whistles (Playing); <= 0: never
  double ready_still_time = 1.0;  // Ready ends early when all stand still in legal places this long
  double still_speed = 0.05;      // m/s: a robot slower than this stands still
  double inactive_time = 10.0;    // s standing idle near the ball before Inactive Player
  // A fallen robot's time and failed get-ups are the rule book's (fallen_time, get_up_attempts).
  // A get-up failed when the robot stood for less than get_up_hold_time before it was down
  // again; the rule book's attempts in a row are Inactive Player, one more when another robot's
  // torso was within get_up_disturbed_distance (torso to torso, on the ground) as one of them
  // failed (the rules: "3 if disturbed" in the SPL, 4 in the HSL).
  double get_up_hold_time = 3.0;           // s
  double get_up_disturbed_distance = 0.6;  // m
  double inactive_ball_distance = 1.0;  // m: "near the ball"
  double inactive_motion = 0.05;        // m the torso must move to count as active
  // Defenders keep the rule book's distance from the ball at a free kick (or out of the penalty
  // area at a goal kick) once this long after it was awarded (time to leave), and as long again
  // as walking out at leave_speed takes a robot that was inside then (the HSL's whole penalty
  // area is 2.95 m deep on the M-Field).
  double free_kick_clear_time = 5.0;  // s
  double leave_speed = 0.2;           // m/s
  double ball_moved = 0.05;           // m: the kicking team moved the ball clearly
  double stuck_progress = 0.3;        // m the ball must move within the game-stuck time
  double stuck_radius = 0.5;          // m: a robot this close to a stuck ball is penalised (local)
  // Pushing: sustained contact between opponents in which one drives into
  // the other, or in which the other falls.
  double push_time = 1.0;  // s of contact (gaps under push_gap count as one) ...
  double push_gap = 0.3;   // s
  double push_displacement =
      0.15;                 // m ... or the other shoved this far since the contact began ...
  double push_speed = 0.1;  // m/s: ... while the pusher moves towards the other this fast
  double foul_ball_distance = 0.5;  // m: pushing this close to the ball in open play is a foul
  // The rules' exceptions for two robots going for the ball within contest_distance of it
  // (torso to ball): front-to-front contact with the ball between them (within
  // contest_corridor of the line joining their torsos), and side contact, the other robot
  // more than contest_angle off the heading of the one walking to the ball.
  double contest_distance = 1.0;   // m
  double contest_corridor = 0.15;  // m
  double contest_angle = std::numbers::pi / 4;  // rad
  // Penalty shoot-out.
  int shootout_goal_side = 1;          // all kicks at the goal at x = side * length / 2
  double ball_stopped_speed = 0.02;    // m/s: the ball has come to a stop ...
  double ball_stopped_time = 0.5;      // ... for this long
  double keeper_line_tolerance = 0.3;  // m: the keeper's torso this far from the goal line left it
  double ball_replayed = 0.3;          // m: the striker touching it again after this ends the kick
};

// The rule for a goal: the whole ball over the goal line (past its far edge)
// between the posts and under the crossbar. +1 / -1: in the goal at +x / -x;
// 0: not in a goal. The referee's own rule, for anyone who judges goals.
int ballInGoal(const fields::FieldModel& field, const engine::Vec3& ball);

// Per link of a robot: whether it belongs to an arm, from the robot's description
// (the limbs hanging from the trunk that hold neither a foot nor a camera; none when
// the description names no legs). For the rule on playing the ball with the arms.
std::vector<char> armLinks(const robots::RobotModel& model);

class Referee {
 public:
  Referee(world::World& world, const RuleBook& rules, const std::array<TeamSetup, 2>& teams,
          int kick_off_team, const RefereeConfig& config = {});

  Game& game() { return game_; }
  const Game& game() const { return game_; }
  // Once per control period, after the world stepped.
  void update();
  // From now on an external GameController runs the game: `packet` is its
  // latest. The referee still removes penalised robots and brings them back
  // and places the ball as the rules say, but its own calls change nothing:
  // they are reported as Advisory events.
  void follow(const ControlData& packet);
  bool following() const { return following_; }

  // The world's robot for (team, player number), if there is one.
  std::optional<world::RobotId> robot(int team, int number) const;
  // The next shoot-out kick (Game::shootoutKick) with the world put in
  // place: ball on the penalty mark, the striker 0.35 m behind it at the
  // penalty area's edge facing the goal, the keeper on the goal line; the
  // other robots leave the field as substitutes.
  void startShootoutKick(int striker, int keeper);

  // Where a penalised robot of `team` waits: 0.5 m outside the touchline,
  // level with its own half's penalty mark, facing the field.
  world::Pose penaltySpot(int team, int index) const;

 private:
  int defenderOfSide(int side) const;  // side -1 / +1: the team defending that goal
  int teamSign(int team) const;        // -1 if the team defends the -x goal now
  void checkBall();
  void checkSetPlayOver();
  void checkPenalties();
  void checkGameStuck();
  void checkShot();
  void checkPushing();
  // Contact between pusher and victim that the rules allow robots going for the ball.
  bool contestingTheBall(world::RobotId pusher, world::RobotId victim,
                         const engine::Vec3& velocity) const;
  void checkArmContact();
  void enterState(gc::State s);
  void onEnterSet();
  void placeForTheSecondHalf();
  // Per robot: in a legal position for the coming kick-off, drop ball or
  // penalty kick (penalised robots count as legal).
  std::vector<char> legalPositions() const;
  engine::Vec3 nearestLegalPosition(world::RobotId r, const std::vector<engine::Vec3>& taken) const;
  fields::AreaSize penaltyArea() const;  // the field's, or the SPL's
  fields::AreaSize goalArea() const;
  double freeKickDistance() const;  // the rule book's, or the field's centre-circle radius
  // How far robot r stands inside the region the opponents of the kicking team keep out of at
  // the current free kick (m to its border; <= 0: outside).
  double depthInAvoidance(world::RobotId r) const;
  double penaltyMarkX(int side) const;  // the mark in front of the goal at x = side * length / 2
  bool inOwnArea(int team, const engine::Vec3& p, const fields::AreaSize& area) const;
  bool inOwnArea(world::RobotId r, const fields::AreaSize& area) const;  // by its torso
  void awardGoalKick(int defender, int side, double y);  // at the goal-area corner on y's side
  double depthInOwnGoalArea(world::RobotId r) const;     // distance to the area's open border (m)
  void placeBall(double x, double y);
  void removePenalised();
  void judge(double dt);  // the automatic referee's rules, applied to game_

  bool following_ = false;
  std::vector<std::string> advised_;  // the calls reported in the last period (following)

  world::World& world_;
  RefereeConfig config_;
  Game game_;
  gc::State last_state_ = gc::State::Initial;
  bool placed_for_second_half_ = false;
  double time_in_state_ = 0.0;
  double still_for_ = 0.0;
  engine::Vec3 set_play_ball_ = engine::Vec3::Zero();  // where the ball was when the set play began
  uint64_t set_play_step_ = 0;                         // world step when it began
  std::vector<double> fallen_for_;
  // Per robot, its get-ups since it last stood for get_up_hold_time.
  struct GetUps {
    bool was_standing = true;
    double stood_up_at = -1e9;  // clock_
    int failed = 0;
    bool disturbed = false;
  };
  std::vector<GetUps> get_ups_;
  // Counts a failed get-up when robot r is down again; true when that is one too many.
  bool getUpsFailed(world::RobotId r, bool standing);
  std::vector<double> idle_for_;            // s standing without moving with the ball near
  std::vector<engine::Vec3> idle_anchor_;   // where the idle time started
  std::vector<double> in_goal_area_since_;  // game time of entering the own goal area; <0 outside
  // Robots of each team (bit = RobotId) that played the ball since the last restart.
  std::array<uint64_t, 2> touched_since_restart_{};
  // The last restart, for the rules on goals straight from it: a kick-off (set play None with a
  // kicking team), a free kick (its set play), a dropped ball (no team); the team that took it,
  // its robots on the field then, and whether its kicker touched the ball outside the centre
  // circle (the HSL's kick-off with two robots or fewer).
  struct Restart {
    gc::SetPlay play = gc::SetPlay::None;
    int team = -1;
    int robots = 0;
    int kicker = -1;  // RobotId of the kicking team's first touch
    bool kicker_outside_circle = false;
    bool kickOff() const { return play == gc::SetPlay::None && team >= 0; }
  };
  Restart restart_;
  void beginRestart();  // from the game's set play and kicking team now
  void noteRestartTouch(world::RobotId r);
  // Why a goal straight from the last restart does not count under the rule book (empty: it
  // counts), and whether an own goal straight from a free kick is a corner kick instead.
  std::string directGoalRefused(int attacker, bool own_goal) const;
  bool ownGoalFromFreeKick(int defender) const;
  uint64_t restart_seen_touch_step_ = 0;
  uint32_t last_set_play_award_ = 0;  // Game::setPlaysAwarded() at the last look
  std::vector<double> clear_by_;  // per robot: clock_ by which it is out of the avoidance region
  double clock_ = 0.0;           // seconds of referee updates, for entry order
  std::vector<bool> parked_;
  std::vector<int> slot_;  // a penalised robot's waiting spot index (kept while it waits), -1 none
  engine::Vec3 stuck_ball_ = engine::Vec3::Zero();
  double stuck_for_ = 0.0;
  // Robots x robots (a < b): s in contact, s since the last contact, and
  // where both stood when the contact began.
  std::vector<double> contact_for_, contact_gap_;
  std::vector<engine::Vec3> contact_start_;
  std::vector<std::vector<char>> arm_link_;  // per robot, per link: an arm
  uint64_t arm_checked_step_ = 0;
  // The running shoot-out kick.
  uint64_t shot_seen_touch_step_ = 0;
  bool striker_touched_ = false, keeper_touched_ = false, hit_post_ = false;
  engine::Vec3 first_touch_ball_ = engine::Vec3::Zero();
  double ball_still_for_ = 0.0;
};

}  // namespace simsoccer::referee
