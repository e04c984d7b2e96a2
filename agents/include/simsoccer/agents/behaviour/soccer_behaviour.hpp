// Soccer behaviour for one robot: what a RoboCup team's behaviour layer
// decides each control period from the robot's perception, the GameState and
// its teammates' messages, handed to the MotionController as a MotionRequest.
//
// Roles: striker (gets behind the ball on the line to the goal, lines up a
// foot, kicks), supporter (beside and behind the ball for the rebound or
// pass), defender (between the ball and the own goal), goalkeeper (on its
// goal line, shifting to the ball's predicted crossing point; clears a ball
// that comes close), penalty kicker and penalty goalkeeper (shoot-out). With
// Role::Auto the goalkeeper is the GameState's goalkeeper number and the field
// players share the other roles by their distance to the ball, announced in
// team messages (TeamMessageCodec, 20 bytes; sent as the SPL message budget
// allows).
//
// The GameState rules: stand in Initial, Standby, Set and while penalised;
// sit in Finished (not in the penalty shoot-out, where Finished is between
// kicks); walk to the kick-off formation in Ready; play in Playing, keeping
// clear of the ball while the opponents take a kick-off or set play, and passing after a
// restart whose goal the rules refuse until another robot of the team played the ball
// (BehaviourConfig::pass_after_restart). Without a GameState (a simulator without a referee
// publishes none) it plays.
//
// Frames: "own" is the field frame turned so that this team attacks +x.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "simsoccer/agents/agent_client.hpp"
#include "simsoccer/agents/motion/motion_controller.hpp"
#include "simsoccer/fields/field_model.hpp"

namespace simsoccer::agents {

enum class Role : uint8_t {
  Auto = 0,
  Striker,
  Supporter,
  Defender,
  Goalkeeper,
  PenaltyKicker,
  PenaltyGoalkeeper
};
const char* roleName(Role r);
std::optional<Role> roleFromName(const std::string& name);

struct BehaviourConfig {
  // Kick-off formation per player number (index 0 = player 1), own frame
  // (x < 0: own half): x and y as shares of the half-length and half-width
  // (so one formation fits any field), yaw in rad. Players beyond the list
  // stand in a line.
  std::vector<Pose2> ready_positions;
  Pose2 kick_off_position{-0.25, 0.0, 0.0};  // the kicking team's striker in Ready
  double max_forward = 0.25, max_side = 0.10, max_turn = 0.8;  // m/s, m/s, rad/s
  double kick_ball_x = 0.17;           // m ahead of the feet's middle, where kicks meet it
  double kick_ball_y = 0.05;           // m sideways: in front of the kicking foot
  double kick_tolerance_x = 0.03;      // m
  double kick_tolerance_y = 0.025;     // m
  double kick_tolerance_angle = 0.15;  // rad off the aim
  double approach_distance = 0.35;     // m behind the ball before lining up
  double ball_lost_time = 3.0;         // s: after this, the own sighting is stale
  // The ball's velocity: the least-squares slope of the own sightings of the
  // last ball_velocity_window, once they span half of it (a ball lying on the
  // penalty mark, seen with 5 % range noise at 100 Hz, must not look like a
  // shot: two sightings a few periods apart read that noise as m/s).
  double ball_velocity_window = 0.3;   // s
  double ball_outlier_distance = 0.3;  // m off the fitted line: left out (a false ball)
  // Sightings in a row (each within 0.1 s and the margin of the one before) that take a ball
  // found away from the one known: false balls come one frame at a time, the ball in view
  // nearly every frame.
  int ball_new_sightings = 3;
  double team_ball_time = 4.0;         // s: a teammate's sighting counts this long
  double keep_clear = 0.8;             // m from the ball at the opponents' kick-off / set play
  // m/s: stepping backwards, facing the ball, out of keep_clear (the rules' referee allows 0.2
  // m/s after the first 5 s; other walks step back at 0.1 at the most).
  double back_off_speed = 0.1;
  // At the opponents' goal kick, out of their whole penalty area as well (the HSL's rule).
  bool goal_kick_clears_penalty_area = false;
  double message_interval = 1.0;       // s, the fastest; slower when the budget asks
  // Where the goalkeeper stands: this far in front of its goal line (m), in
  // play and as the shoot-out's keeper (the rules keep it on the line).
  double keeper_line = 0.25;
  double shootout_keeper_line = 0.05;
  // The goalkeeper blocks (MotionRequest::Kind::Block) a ball coming at its
  // goal faster than block_speed that will pass it within block_time, no
  // further sideways than block_reach from its middle.
  double block_speed = 0.4;   // m/s
  double block_time = 0.6;    // s
  double block_reach = 0.35;  // m
  // The penalty goalkeeper dives (MotionRequest::Kind::Dive) at a ball out of
  // the block's reach but within dive_reach, passing within dive_time. (Only
  // in the shoot-out: a dive ends on the ground, and one shot is all there is.)
  double dive_time = 0.9;   // s
  double dive_reach = 0.8;  // m
  // Other robots seen within avoid_far ahead of the walk slow its approach to
  // them, down to none at avoid_near, and turn it into a step past them
  // (robots that walk into each other fall). Within avoid_ball of the ball in
  // play only from a teammate nearer the ball: the ball is contested with the
  // opponents there, and the referee's pushing rule decides.
  double avoid_near = 0.45;  // m, torso to torso
  double avoid_far = 1.0;    // m
  double avoid_ball = 0.6;   // m
  // A robot seen is kept where it was seen (on the field, moved with the own
  // pose) for obstacle_memory after it left the cameras' view: with the head
  // turned to the ball the robots beside and behind are out of view, and
  // turning or stepping sideways into them made robots fall in crowds.
  double obstacle_memory = 2.0;  // s
  // Two or more defenders stand side by side across the line from the ball
  // to the own goal, defender_spacing apart (each would otherwise walk to the
  // same spot, and they met there, and fell; 0 puts them there again).
  double defender_spacing = 1.2;  // m
  // Defenders stand no nearer their goal line than this (the goalkeeper stands at keeper_line).
  double defender_goal_distance = 0.8;  // m
  // The supporter stands 1.2 m behind and beside the ball, but not deeper than this (own
  // frame x, a share of the half-length): with the ball near the own goal, behind it was
  // among the defenders and the goalkeeper, and the robots there walked into each other.
  double supporter_deepest = -0.5;
  // A ball so near the own goal line that the place behind it to line up from (towards the
  // opponent goal) would lie less than 0.1 m in front of the line is cleared at the angle that
  // keeps the place there, at most this far (rad) off the field's length, to the side whose
  // place is nearer. 0: off (lined up towards the goal, from inside the own goal if need be).
  double clear_max_angle = 0.0;
  // The striker waiting in front of the own goal area while the goalkeeper plays the ball there
  // stands this far (m) beside the line from the ball to the opponent goal, the keeper's
  // clearance: in front of the ball it stopped the clearances, and some came back into the goal.
  double keeper_lane = 0.6;
  // A walk keeps the torso this far (m) from the goals' posts and nets, and between the posts
  // no further than 0.1 m behind a goal line (one further in than 0.15 m walks out through the
  // mouth): robots walked into their own goal, stepping past a teammate or after a ball beside
  // the post, and fell against the net.
  double goal_clearance = 0.25;
  // When a half or the game is over: sit down and rest, as Naos do (the SPL's habit: cool
  // joints), or stand (the K1: its crouch right after a get-up tips it forward, and a robot
  // down at the whistle fell again and again through the half-time).
  bool sit_when_finished = true;
  // After which restarts a goal counts only once another robot of the team has played the ball
  // (the rule book's; agents cannot read it from the GameState): then the striker passes to a
  // teammate instead of shooting, until a teammate says (TeamMessageData::kicked) that it kicked
  // the ball since the restart. EveryRestart: the SPL's two-touch rule (after any restart but a
  // penalty kick, both teams); OwnKickOffAndKickIn: the HSL's (no goal straight from the own
  // kick-off or kick-in: another robot of either team must touch the ball), where the restart's
  // kick itself is the pass (an opponent's touch counts, and the agents see no touches); None:
  // shoot at once.
  enum class PassRule : uint8_t { None, EveryRestart, OwnKickOffAndKickIn };
  PassRule pass_after_restart = PassRule::None;
  // m: a pass goes to a teammate this far from the ball (the nearest and the farthest).
  double pass_min = 1.0, pass_max = 4.0;
};
// Reads configs/agents/*.yaml; throws engine::ConfigError (file, key, reason).
BehaviourConfig loadBehaviourConfig(const std::filesystem::path& file);
// A kick approach's (agents/behaviour/kick_approach.hpp) from a file with only these keys of a
// behaviour config: max_forward, max_side, max_turn, kick_ball, kick_tolerance,
// approach_distance (read and checked as there); the others keep their defaults.
BehaviourConfig loadKickApproach(const std::filesystem::path& file);

// What one robot tells its teammates (field frame), in 20 bytes.
struct TeamMessageData {
  int player = 0;
  Role role = Role::Auto;
  bool fallen = false, ball_seen = false;
  // It kicked the ball since the last restart under the pass rule (pass_after_restart).
  bool kicked = false;
  double x = 0, y = 0, yaw = 0;   // m, m, rad
  double ball_x = 0, ball_y = 0;  // m
  double ball_age = 0;            // s since seen
  double cost = 0;                // the striker bid: lower is better (m)
};
std::vector<uint8_t> encodeTeamMessage(const TeamMessageData& d);
std::optional<TeamMessageData> decodeTeamMessage(const std::vector<uint8_t>& bytes);

class SoccerBehaviour {
 public:
  SoccerBehaviour(const BehaviourConfig& config, const fields::FieldModel& field, int team,
                  int team_number, int player, Role role, uint64_t seed);

  struct Vec2 {
    double x = 0, y = 0;
  };
  struct Input {
    double time = 0.0;                              // s of simulated time
    const PerceptionIn* perception = nullptr;       // this period's, if any
    const simsoccer_msg_GameState* game = nullptr;  // the latest, if any
    MotionState motion = MotionState::Stance;
    // The feet's midpoint in the robot frame (m; MotionController::feetCentre): a kick lines
    // the ball up against it, not against the swaying torso.
    Vec2 feet{};
    // Down: falling, lying, getting up or diving (from the motion state).
    bool fallen() const {
      return motion == MotionState::Falling || motion == MotionState::Lying ||
             motion == MotionState::GettingUp || motion == MotionState::Diving;
    }
  };
  MotionRequest update(const Input& in);
  // Teammates' messages as they arrive (stamped with the period they were sent in).
  void receive(const TeamMessageIn& message, double time);
  // A message to send this period, if it is time for one (budget allowing).
  std::optional<std::vector<uint8_t>> outgoing(const Input& in);
  // True once after the robot was moved by the referee (penalty, placement):
  // the motion layer should start over from the stance.
  bool takeMotionRestart();

  Role role() const { return role_; }  // the role in force (never Auto)
  const BehaviourConfig& config() const { return config_; }
  // Where the last update walked to or aimed at, in the own team's frame (own goal at -x).
  Pose2 target() const { return target_; }
  std::string status() const;          // one line: role, game state, ball, target

 private:
  struct Teammate {
    TeamMessageData data;
    double received = -1.0;
  };
  void readGame(const Input& in);
  void updateBall(const Input& in);
  // Robots in view into obstacles_, and robots_seen_ from those seen within obstacle_memory.
  void rememberRobots(const std::vector<PerceivedIn>& robots, double time);
  Role chooseRole(const Input& in);
  MotionRequest play(const Input& in);
  // A player's kick-off place, own frame, as shares of the half-length and half-width
  // (config ready_positions; players beyond the list stand in a line).
  Pose2 readyPosition(int player) const;
  MotionRequest ready();
  MotionRequest striker(double aim_y, bool penalty);
  MotionRequest goalkeeper(bool shootout);
  // Whether a field-frame (own) point lies in the own goal area.
  bool inOwnGoalArea(const Vec2& p) const;
  // The team's goalkeeper plays, by its last message: heard from recently, not
  // penalised, not fallen.
  bool keeperInPlay(double time) const;
  struct Crossing {
    double t, y;  // s from now; m, own frame
  };
  // When and where the ball, rolling towards the own goal (-x) faster than
  // `speed` m/s, crosses the line at own-frame x; nothing if it does not.
  std::optional<Crossing> ballCrossing(double x, double speed) const;
  // Beyond turn_beyond (m) the robot turns towards the target and walks; nearer it steps there
  // as it faces (target.yaw, or the ball), backwards at max_backward (m/s) at the most.
  static constexpr double kTurnToWalkBeyond = 0.5;  // m
  static constexpr double kMaxBackward = 0.1;       // m/s
  MotionRequest walkTo(const Pose2& target, bool face_ball, double turn_beyond = kTurnToWalkBeyond,
                       double max_backward = kMaxBackward);
  void avoidRobots(MotionRequest& r) const;
  // Takes away the walk's speed into either goal (goal_clearance).
  void avoidGoals(MotionRequest& r) const;
  // Whether own-frame p lies behind the own goal line within the goal's width, its posts and
  // goal_clearance (a place to line up from there is in the goal or against its frame).
  bool inOwnGoalFrame(const Vec2& p) const;
  // The head's angles into r; `planned` is the walk before avoidRobots.
  void head(MotionRequest& r, const MotionRequest& planned, const Input& in);
  Vec2 toOwn(double fx, double fy) const;    // field -> own frame
  Vec2 fromOwn(double ox, double oy) const;  // own -> field frame
  Vec2 toRobot(const Vec2& own) const;       // own -> robot frame
  Vec2 fromRobot(const Vec2& robot) const;   // robot -> own frame (from where it is now)

  BehaviourConfig config_;
  fields::FieldModel field_;
  int team_;  // the world's team index (0, 1), as perception labels robots
  int team_number_, player_;
  Role fixed_role_, role_ = Role::Striker;
  // As a defender: its place among the defenders, from the left (+y, own frame), and their number.
  size_t defender_slot_ = 0, defenders_ = 1;
  // As a supporter: the side of the ball it keeps (+1 left, -1 right, own frame; 0: not one).
  double supporter_side_ = 0.0;
  // Clearing a ball near the own goal line: the side it is kicked to (+1 left, -1 right, own
  // frame; 0: not clearing), kept while it lasts (calls no more than 0.5 s apart) so that a
  // sighting either side of the kicker does not turn it back and forth.
  double clear_side_ = 0.0, cleared_at_ = 0.0;
  // A ball too deep for the defenders to stand between it and their goal: they stand wide.
  bool defenders_wide_ = false;
  // Game.
  bool have_game_ = false;
  int state_ = 3;  // gc::State numbering; Playing without a GameState
  int set_play_ = 0, phase_ = 0;
  bool our_kick_ = false, kick_pending_ = false, penalised_ = false, was_penalised_ = false;
  // Per player number (index = number - 1), by the GameState: out of play.
  std::array<bool, protocol::kMaxPlayers> team_penalised_{};
  bool penalisedInGame(int player) const {
    return player >= 1 && player <= static_cast<int>(team_penalised_.size()) &&
           team_penalised_[static_cast<size_t>(player - 1)];
  }
  int attack_sign_ = 1;  // +1: this team attacks +x
  int goalkeeper_number_ = 1, players_per_team_ = 5, secs_remaining_ = 600, budget_ = 1200;
  bool first_half_ = true;
  int last_state_ = -1;
  bool restart_motion_ = false;
  // Self and ball (own frame).
  Pose2 self_;
  bool self_known_ = false;
  Vec2 ball_, ball_robot_;  // own frame; robot frame (the last own sighting taken)
  double ball_seen_at_ = -1e9, ball_known_at_ = -1e9;
  // The last sighting at all, taken or not (robot frame), and how many in a row agreed with
  // the one before: a sighting far from the ball is taken once ball_new_sightings agree.
  Vec2 sighting_robot_;
  Vec2 feet_;  // Input::feet
  double sighting_at_ = -1e9;
  int sightings_in_row_ = 0;
  Vec2 ball_velocity_;
  struct Sighting {
    double time;
    Vec2 ball;     // own frame
    bool outlier;  // left out of the last fit
  };
  std::deque<Sighting> sightings_;  // own, in view, the last ball_velocity_window
  struct SeenRobot {
    Vec2 at;  // robot frame
    bool teammate;
  };
  std::vector<SeenRobot> robots_seen_;  // other robots seen within obstacle_memory
  struct RememberedRobot {
    Vec2 at;             // own frame, where it was last seen
    double seen = -1e9;  // s
    bool teammate = false;
  };
  std::vector<RememberedRobot> obstacles_;  // per perceived robot, in perception's order
  void updateBallVelocity(double time, const Vec2& ball);
  void forgetBallTrack();
  std::vector<Teammate> mates_;
  double last_sent_ = -1e9, now_ = 0.0;
  Role last_sent_role_ = Role::Auto;  // the role in the last message sent
  Leg kick_foot_ = Leg::Right;
  // A kick once decided is kept asked for (the walk stops first) until the
  // motion layer is seen kicking, or this time passes.
  double kick_commit_until_ = -1.0;
  double penalty_aim_ = 0.5;  // -1..1: right post .. left post
  Pose2 target_;
  bool arrived_ = false;  // at the walk target: standing
  // The pass rule (BehaviourConfig::pass_after_restart): since when it holds for this team
  // (-1: it does not); when this robot last kicked; when a message last came from a teammate
  // that kicked since (the time it was received).
  double pass_rule_since_ = -1.0, kicked_at_ = -1e9, mate_kicked_at_ = -1e9;
  int last_set_play_ = 0, last_kicking_team_ = -1, last_secondary_time_ = 0;
  int pass_to_ = 0;  // the teammate the last pass was aimed at (player number; 0: none)
  bool last_sent_kicked_ = false;  // TeamMessageData::kicked in the last message sent
  bool kickedSinceRestart() const {
    return pass_rule_since_ >= 0.0 && kicked_at_ >= pass_rule_since_;
  }
  // The rule holds and no teammate has said it kicked the ball since the restart (with this
  // robot's touch, that teammate's makes two); under the HSL's rule, nor has this robot.
  bool passRequired() const;
  // Where a pass goes (own frame): the teammate in play furthest up the field among those
  // pass_min to pass_max from the ball, not deeper than the own penalty area and, from a ball in
  // the own half beyond the centre circle, not behind the ball; under the HSL's rule with the
  // goal beyond pass_max from the ball, only one ahead of it (the one aimed at before while it
  // still is one); none if there is none.
  std::optional<Vec2> passTarget();
};

}  // namespace simsoccer::agents
