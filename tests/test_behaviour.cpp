// The agents' behaviour layer and what it stands on: team message codec,
// behaviour config errors, role assignment by team messages, GameState
// obedience, the striker lining up and kicking; keyframe motions and the
// motion controller's fall detector; the match log format.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <random>

#include "simsoccer/agents/behaviour/kick_approach.hpp"
#include "simsoccer/agents/behaviour/soccer_behaviour.hpp"
#include "simsoccer/agents/soccer_agent.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/protocol/gamecontroller.hpp"
#include "simsoccer/world/match_log.hpp"
#include "simsoccer/world/scenario.hpp"
#include "test_support.hpp"

using namespace simsoccer;
using agents::MotionRequest;
using agents::Role;
using engine::Vec3;

namespace {

agents::BehaviourConfig soccerConfig() {
  return agents::loadBehaviourConfig(test::sourceDir() / "configs/agents/soccer.yaml");
}
fields::FieldModel field() {
  return fields::loadFieldModel(test::splField());
}

// A perception with the robot at (x, y, yaw) and the ball at field (bx, by), seen.
agents::PerceptionIn seeing(double x, double y, double yaw, double bx, double by, double t) {
  agents::PerceptionIn p;
  p.sim_time = t;
  p.self_pose = {static_cast<float>(x), static_cast<float>(y), static_cast<float>(yaw)};
  const double dx = bx - x, dy = by - y, c = std::cos(yaw), s = std::sin(yaw);
  p.ball.in_view = true;
  p.ball.last_seen = t;
  p.ball.x = static_cast<float>(c * dx + s * dy);
  p.ball.y = static_cast<float>(-s * dx + c * dy);
  return p;
}

// A behaviour takes a sighting of a new ball once ball_new_sightings in a row agree (a false
// ball lasts one frame): a test's first sighting is given that often, 0.01 s apart.
MotionRequest updateSeeing(agents::SoccerBehaviour& b, agents::SoccerBehaviour::Input in) {
  const double t = in.time;
  for (int i = b.config().ball_new_sightings - 1; i > 0; --i) {
    in.time = t - 0.01 * i;
    b.update(in);
  }
  in.time = t;
  return b.update(in);
}

simsoccer_msg_GameState gameState(int state, int team0_number = 1) {
  simsoccer_msg_GameState g{};
  g.state = static_cast<uint8_t>(state);
  g.players_per_team = 5;
  g.first_half = 1;
  g.kicking_team = 255;
  g.secs_remaining = 600;
  g.teams[0].team_number = static_cast<uint8_t>(team0_number);
  g.teams[1].team_number = static_cast<uint8_t>(team0_number == 1 ? 2 : 1);
  for (auto& t : g.teams) {
    t.goalkeeper = 1;
    t.message_budget = 1200;
  }
  return g;
}

// A teammate's message: its pose and its striker bid (the distance to the ball).
agents::TeamMessageIn mate(int player, double x, double y, double cost) {
  agents::TeamMessageData d;
  d.player = player;
  d.x = x;
  d.y = y;
  d.cost = cost;
  agents::TeamMessageIn m;
  m.from_player = player;
  m.data = agents::encodeTeamMessage(d);
  return m;
}

// The motion controller with the get-up off (as `simsoccer-agent --no-get-up` runs it).
agents::MotionController controllerWithoutGetUp(const robots::RobotModel& model) {
  agents::FallDetectorParameters fall;
  fall.get_up = false;
  return agents::loadMotionController(model, test::sourceDir() / "configs/motions", fall);
}

// One control period of robot 0 driven by `mc`.
void controlPeriod(world::World& w, agents::MotionController& mc, const MotionRequest& request,
                   std::vector<float>& position, std::vector<float>& stiffness) {
  mc.update(w.scenario().physics.control_period, agents::motionSensors(w.sensorFrame(0)), request,
            position, stiffness);
  w.setCommand(0, std::span<const float>(position), std::span<const float>(stiffness));
  w.stepControlPeriod();
}

// Runs `period` (one control period) `periods` times: robot 0's lowest torso
// height meanwhile, m.
template <class Period>
double lowestTorsoOver(const world::World& w, Period&& period, int periods) {
  double lowest = 1.0;
  for (int i = 0; i < periods; ++i) {
    period();
    lowest = std::min(lowest, w.torsoPose(0).translation().z());
  }
  return lowest;
}

// Lying on its front at (-2, 0).
engine::Pose onItsFront() {
  engine::Pose lying = engine::Pose::Identity();
  lying.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  lying.translation() = Vec3(-2.0, 0.0, 0.16);
  return lying;
}

// One Nao driven by a motion controller with the get-up on, stood for 1 s, then put down on
// its front and run until its get-up starts.
struct GettingUp {
  world::World w{test::scenario(1)};
  agents::MotionController mc{agents::loadMotionController(
      *w.robot(0).model, test::sourceDir() / "configs/motions", agents::FallDetectorParameters{})};
  std::vector<float> position = std::vector<float>(25), stiffness = std::vector<float>(25);
  MotionRequest request;

  GettingUp() {
    for (int i = 0; i < 100; ++i) period();
    w.placeRobot(0, onItsFront(), "stand");
    for (int i = 0; i < 300 && mc.state() != agents::MotionState::GettingUp; ++i) period();
  }
  void period() { controlPeriod(w, mc, request, position, stiffness); }
};

}  // namespace

TEST(TeamMessage, RoundTripsWithinTheSplBudgetSize) {
  agents::TeamMessageData d;
  d.player = 4;
  d.role = Role::Defender;
  d.fallen = true;
  d.ball_seen = true;
  d.x = -2.345;
  d.y = 1.5;
  d.yaw = -3.0;
  d.ball_x = 4.4;
  d.ball_y = -2.9;
  d.ball_age = 1.3;
  d.cost = 2.71;
  const auto bytes = agents::encodeTeamMessage(d);
  EXPECT_EQ(bytes.size(), 20u);
  EXPECT_LE(bytes.size(), 128u);  // SPL limit
  const auto back = agents::decodeTeamMessage(bytes);
  ASSERT_TRUE(back);
  EXPECT_EQ(back->player, 4);
  EXPECT_EQ(back->role, Role::Defender);
  EXPECT_TRUE(back->fallen && back->ball_seen);
  EXPECT_FALSE(back->kicked);
  d.kicked = true;
  d.fallen = false;
  const auto kicked = agents::decodeTeamMessage(agents::encodeTeamMessage(d));
  ASSERT_TRUE(kicked);
  EXPECT_TRUE(kicked->kicked && kicked->ball_seen && !kicked->fallen);
  EXPECT_NEAR(back->x, d.x, 1e-3);
  EXPECT_NEAR(back->yaw, d.yaw, 1e-3);
  EXPECT_NEAR(back->ball_y, d.ball_y, 1e-3);
  EXPECT_NEAR(back->ball_age, 1.3, 0.05);
  EXPECT_NEAR(back->cost, 2.71, 0.01);
  // Other teams' formats and garbage are ignored, not misread.
  auto bad = bytes;
  bad[0] = 'X';
  EXPECT_FALSE(agents::decodeTeamMessage(bad));
  EXPECT_FALSE(agents::decodeTeamMessage({1, 2, 3}));
}

TEST(BehaviourConfig, ErrorsNameFileAndKey) {
  const test::TempDir dir("behaviour_cfg");
  const auto f = dir / "bad.yaml";
  std::ofstream(f) << "behaviour: soccer\nready_positions: [[0, 0, 0]]\nmax_forward: -1\n";
  try {
    agents::loadBehaviourConfig(f);
    FAIL() << "accepted a negative speed";
  } catch (const engine::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("max_forward"), std::string::npos);
  }
  std::ofstream(f) << "behaviour: soccer\nready_positions: [[0, 0]]\n";
  EXPECT_THROW(agents::loadBehaviourConfig(f), engine::ConfigError);
  std::ofstream(f) << "behaviour: soccer\nready_positions: []\nmax_fowrard: 1\n";
  EXPECT_THROW(agents::loadBehaviourConfig(f), engine::ConfigError);  // a typo
  // The key a config with `line` added is refused at ("" when it is accepted).
  const auto refusedAt = [&](const std::string& line) -> std::string {
    std::ofstream(f) << "behaviour: soccer\nready_positions: []\n" << line << "\n";
    try {
      agents::loadBehaviourConfig(f);
    } catch (const engine::ConfigError& e) {
      return e.key();
    }
    return "";
  };
  EXPECT_EQ(refusedAt("keeper_line: -0.1"), "keeper_line");  // behind the goal line
  EXPECT_EQ(refusedAt("avoid_far: 0.4"), "avoid_far");       // under avoid_near (0.45)
  EXPECT_EQ(refusedAt("avoid_near: 1.1"), "avoid_near");     // over avoid_far (1.0)
  EXPECT_EQ(refusedAt("avoid_ball: -1"), "avoid_ball");
  EXPECT_EQ(refusedAt("ball_velocity_window: 0.01"), "ball_velocity_window");
  EXPECT_EQ(refusedAt("ball_outlier_distance: 0"), "ball_outlier_distance");
  EXPECT_EQ(refusedAt("ball_new_sightings: 1"), "ball_new_sightings");  // a false ball taken
  EXPECT_EQ(refusedAt("ball_new_sightings: 2.5"), "ball_new_sightings");
  EXPECT_EQ(refusedAt("obstacle_memory: -1"), "obstacle_memory");
  EXPECT_EQ(refusedAt("defender_goal_distance: -0.5"), "defender_goal_distance");
  EXPECT_EQ(refusedAt("supporter_deepest: -1.5"), "supporter_deepest");  // behind the goal line
  EXPECT_EQ(refusedAt("clear_max_angle: 1.6"), "clear_max_angle");       // cleared backwards
  EXPECT_EQ(refusedAt("clear_max_angle: -0.1"), "clear_max_angle");
  EXPECT_EQ(refusedAt("avoid_ball: 0"), "");  // none: never give way at the ball
  EXPECT_EQ(refusedAt("pass_after_restart: sometimes"), "pass_after_restart");
  EXPECT_EQ(refusedAt("pass_distance: [2, 1]"), "pass_distance");  // nearest beyond farthest
  EXPECT_EQ(refusedAt("pass_distance: [0, 3]"), "pass_distance");
  EXPECT_EQ(refusedAt("pass_distance: [1]"), "pass_distance");
  EXPECT_EQ(refusedAt("pass_distance: [1, 3]"), "");
  EXPECT_EQ(refusedAt("back_off_speed: 0"), "back_off_speed");
  EXPECT_EQ(refusedAt("back_off_speed: 0.2"), "");
  EXPECT_EQ(refusedAt("keeper_lane: -0.1"), "keeper_lane");
  EXPECT_EQ(refusedAt("keeper_lane: 0"), "");
  EXPECT_EQ(refusedAt("goal_clearance: -0.05"), "goal_clearance");
  EXPECT_EQ(refusedAt("goal_clearance: 0"), "");
}

TEST(BehaviourConfig, AConfigStartsFromItsBaseAndChangesSomeKeys) {
  // The HSL Small division's Naos: the SPL's behaviour with the HSL's goal-kick rule.
  const auto spl = soccerConfig();
  const auto hsl =
      agents::loadBehaviourConfig(test::sourceDir() / "configs/agents/soccer_hsl_small.yaml");
  EXPECT_FALSE(spl.goal_kick_clears_penalty_area);
  EXPECT_TRUE(hsl.goal_kick_clears_penalty_area);
  EXPECT_EQ(hsl.ready_positions.size(), spl.ready_positions.size());
  EXPECT_EQ(hsl.keep_clear, 0.95);  // the S-Field's free-kick distance and a margin
  EXPECT_EQ(hsl.avoid_near, spl.avoid_near);
  EXPECT_EQ(hsl.kick_ball_x, spl.kick_ball_x);
  EXPECT_EQ(hsl.sit_when_finished, spl.sit_when_finished);
  // A bad key in the file or its base is refused naming that file; a loop ends.
  const test::TempDir dir("behaviour_base");
  std::ofstream(dir / "base.yaml") << "ready_positions: [[0, 0, 0]]\nkeep_clear: 0.5\n";
  std::ofstream(dir / "top.yaml") << "base: base.yaml\nkeep_clear: 1.2\n";
  const auto top = agents::loadBehaviourConfig(dir / "top.yaml");
  EXPECT_EQ(top.keep_clear, 1.2);
  EXPECT_EQ(top.ready_positions.size(), 1u);
  std::ofstream(dir / "base.yaml") << "ready_positions: [[0, 0, 0]]\nkeep_cler: 0.5\n";
  try {
    agents::loadBehaviourConfig(dir / "top.yaml");
    ADD_FAILURE() << "a typo in the base accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_NE(e.file().find("base.yaml"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "top.yaml") << "base: top.yaml\n";
  EXPECT_THROW(agents::loadBehaviourConfig(dir / "top.yaml"), engine::ConfigError);
  std::ofstream(dir / "base.yaml") << "ready_positions: [[0, 0, 0]]\n";
  std::ofstream(dir / "top.yaml") << "base: base.yaml\ngoal_kick_avoidance: goal_area\n";
  try {
    agents::loadBehaviourConfig(dir / "top.yaml");
    ADD_FAILURE() << "a bad goal_kick_avoidance accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "goal_kick_avoidance");
  }
}

TEST(SoccerBehaviour, UnderTheHslRulesItLeavesThePenaltyAreaAtTheOpponentsGoalKick) {
  const auto f = field();
  const double front = f.halfLength() - f.penalty_area->length;
  // Team 0's striker in the opponents' penalty area, 0.67 m from their goal kick's ball (the
  // goal-area corner), nearer their goal line.
  const double bx = f.halfLength() - f.goal_area->length, by = 0.5 * f.goal_area->width;
  for (const bool hsl : {false, true}) {
    agents::SoccerBehaviour b(hsl ? agents::loadBehaviourConfig(
                                        test::sourceDir() / "configs/agents/soccer_hsl_small.yaml")
                                  : soccerConfig(),
                              f, 0, 1, 4, Role::Striker, 1);
    auto g = gameState(3);
    g.kicking_team = 2;  // the opponents
    g.set_play = static_cast<uint8_t>(protocol::gc::SetPlay::GoalKick);
    g.secondary_time = 30;
    auto p = seeing(bx + 0.3, by - 0.6, 0.0, bx, by, 0.5);
    agents::SoccerBehaviour::Input in;
    in.time = 0.5;
    in.perception = &p;
    in.game = &g;
    const MotionRequest r = updateSeeing(b, in);
    EXPECT_EQ(r.kind, MotionRequest::Kind::Walk) << hsl;
    // The SPL's: straight away from the ball, deeper into the area; the HSL's: out of it.
    if (hsl) {
      EXPECT_LT(b.target().x, front) << b.target().x;
    } else {
      EXPECT_GT(b.target().x, front) << b.target().x;
    }
  }
  // A K1 on the M-Field by its goal line, 2.1 m from the ball: the nearer edge (the side) lies
  // past the ball, within keep_clear of it; it leaves by the front, 0.3 m out, as it stands.
  const auto m = fields::loadFieldModel(test::sourceDir() / "fields/hsl_m.yaml");
  const auto k1 = agents::loadBehaviourConfig(test::sourceDir() / "configs/agents/soccer_k1.yaml");
  const double mx = m.halfLength() - m.goal_area->length, my = 0.5 * m.goal_area->width;
  const double x = m.halfLength() - 0.025, y = 0.1;
  ASSERT_GT(std::hypot(x - mx, y - my), k1.keep_clear);
  ASSERT_LT(0.5 * m.penalty_area->width - y, x - (m.halfLength() - m.penalty_area->length));
  agents::SoccerBehaviour b(k1, m, 0, 1, 4, Role::Striker, 1);
  auto g = gameState(3);
  g.kicking_team = 2;
  g.set_play = static_cast<uint8_t>(protocol::gc::SetPlay::GoalKick);
  g.secondary_time = 30;
  auto p = seeing(x, y, M_PI, mx, my, 0.5);
  agents::SoccerBehaviour::Input in;
  in.time = 0.5;
  in.perception = &p;
  in.game = &g;
  EXPECT_EQ(updateSeeing(b, in).kind, MotionRequest::Kind::Walk);
  EXPECT_NEAR(b.target().x, m.halfLength() - m.penalty_area->length - 0.4, 1e-6);
  EXPECT_NEAR(b.target().y, y, 1e-6);
}

// At the opponents' free kick a robot inside keep_clear steps backwards out of it, facing the ball,
// at back_off_speed, to just beyond it straight away from the ball; from beyond it, it stands
// where its role would take it inside. (Walking to a place as far again from the ball turned a
// K1 1.2 m from it round for 5 s, and stepped one 0.4 m from it back at 0.1 m/s.)
TEST(SoccerBehaviour, AtTheOpponentsFreeKickItStepsBackOutOfTheCircleFacingTheBall) {
  const auto f = field();
  for (const bool k1 : {false, true}) {
    const auto cfg =
        k1 ? agents::loadBehaviourConfig(test::sourceDir() / "configs/agents/soccer_k1.yaml")
           : soccerConfig();
    EXPECT_EQ(cfg.back_off_speed, k1 ? 0.25 : 0.1);
    const double out = cfg.keep_clear + 0.1;
    auto g = gameState(3);
    g.kicking_team = 2;  // the opponents
    g.set_play = static_cast<uint8_t>(protocol::gc::SetPlay::PushingFreeKick);
    g.secondary_time = 30;
    // (distance from the ball, the robot's yaw, the side it stands on): facing the ball, or
    // turned away from it, from in front of it and from beside it.
    struct Case {
      double distance, yaw_off_ball;
      int side;
    };
    for (const Case c : {Case{0.4, 0.0, 0}, Case{0.75 * cfg.keep_clear, 0.0, 0}, Case{0.6, 0.0, 1},
                         Case{0.5, 2.5, 0}}) {
      agents::SoccerBehaviour b(cfg, f, 0, 1, 4, Role::Striker, 1);
      const double bx = 1.0, by = 0.5;
      const double dir = c.side == 0 ? M_PI : -0.5 * M_PI;  // from the ball to the robot
      const double x = bx + c.distance * std::cos(dir), y = by + c.distance * std::sin(dir);
      const double yaw = dir + M_PI + c.yaw_off_ball;
      auto p = seeing(x, y, yaw, bx, by, 0.5);
      agents::SoccerBehaviour::Input in;
      in.time = 0.5;
      in.perception = &p;
      in.game = &g;
      const MotionRequest r = updateSeeing(b, in);
      const std::string what = std::to_string(k1) + " " + std::to_string(c.distance) + " " +
                               std::to_string(c.yaw_off_ball) + " " + std::to_string(c.side);
      ASSERT_EQ(r.kind, MotionRequest::Kind::Walk) << what;
      EXPECT_NEAR(b.target().x, bx + out * std::cos(dir), 1e-6) << what;
      EXPECT_NEAR(b.target().y, by + out * std::sin(dir), 1e-6) << what;
      if (c.yaw_off_ball == 0.0) {
        // Facing the ball: straight backwards at the back-off speed, no turning round.
        EXPECT_NEAR(r.forward, -cfg.back_off_speed, 1e-6) << what;
        EXPECT_NEAR(r.left, 0.0, 1e-6) << what;
        EXPECT_NEAR(r.turn, 0.0, 1e-6) << what;
      } else {
        EXPECT_GT(r.forward, 0.0) << what;  // the way out lies ahead of it
        EXPECT_LT(r.turn, 0.0) << what;     // turning back to the ball
      }
    }
    // Beyond keep_clear, with its role's place (behind the ball) inside: it stands.
    agents::SoccerBehaviour b(cfg, f, 0, 1, 4, Role::Striker, 1);
    auto p = seeing(1.0 - cfg.keep_clear - 0.2, 0.5, 0.0, 1.0, 0.5, 0.5);
    agents::SoccerBehaviour::Input in;
    in.time = 0.5;
    in.perception = &p;
    in.game = &g;
    EXPECT_EQ(updateSeeing(b, in).kind, MotionRequest::Kind::Stand) << k1;
  }
}

// Where the rules refuse a goal straight from a restart, the striker passes: the SPL's two-touch
// rule after any restart but a penalty kick, the HSL's after the own kick-off and kick-in. It
// aims at the teammate furthest up the field within reach (not one too near, too far, deeper
// than the own penalty area or the goalkeeper), and at the goal again once a teammate has said
// it kicked the ball since the restart (a message about the restart before does not count).
TEST(SoccerBehaviour, AfterARestartWhoseGoalNeedsASecondRobotTheStrikerPasses) {
  const auto f = field();
  const double bx = 1.0, by = 2.9;  // the ball at a kick-in, near the left touchline (own frame)
  // A teammate's message: its pose (own frame, turned into the field's by `sign`), role, kick.
  const auto message = [](int player, double x, double y, Role role, bool kicked, double sign) {
    agents::TeamMessageData d;
    d.player = player;
    d.x = sign * x;
    d.y = sign * y;
    d.role = role;
    d.kicked = kicked;
    d.cost = 3.0;
    return agents::TeamMessageIn{player, 0, agents::encodeTeamMessage(d)};
  };
  enum class Mate { None, KickedBefore, KickedSince };
  // The striker's aim (its target's yaw, own frame) at `play` taken by `kicking` (a team
  // number), attacking +x (team 0's number first) or -x; `mate`: teammate 3 says it kicked,
  // 0.3 s before the restart or 1.5 s after it.
  const auto aim = [&](const agents::BehaviourConfig& cfg, protocol::gc::SetPlay play, int kicking,
                       Mate mate, bool attack_minus_x = false) {
    const double sign = attack_minus_x ? -1.0 : 1.0;
    agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Striker, 1);
    b.receive(message(3, 0.5, 0.5, Role::Supporter, false, sign), 0.2);   // 2.45 m: the pass
    b.receive(message(4, 1.5, 2.2, Role::Defender, false, sign), 0.2);    // 0.86 m: too near
    b.receive(message(5, -2.9, 2.6, Role::Defender, false, sign), 0.2);   // 3.91 m: in the area
    b.receive(message(6, 4.2, -1.5, Role::Supporter, false, sign), 0.2);  // 5.5 m: too far
    b.receive(message(1, 2.0, 1.0, Role::Goalkeeper, false, sign), 0.2);  // the goalkeeper
    if (mate == Mate::KickedBefore)
      b.receive(message(3, 0.5, 0.5, Role::Supporter, true, sign), 0.2);
    auto g = gameState(3, attack_minus_x ? 2 : 1);
    g.kicking_team = static_cast<uint8_t>(kicking);
    g.set_play = static_cast<uint8_t>(play);
    g.secondary_time = 30;
    auto p = seeing(sign * 0.2, sign * 2.3, attack_minus_x ? M_PI : 0.0, sign * bx, sign * by, 0.5);
    agents::SoccerBehaviour::Input in;
    in.time = 0.5;
    in.perception = &p;
    in.game = &g;
    updateSeeing(b, in);
    if (mate == Mate::KickedSince) {
      b.receive(message(3, 0.5, 0.5, Role::Supporter, true, sign), 2.0);
      in.time = 2.1;
      p = seeing(sign * 0.2, sign * 2.3, attack_minus_x ? M_PI : 0.0, sign * bx, sign * by, 2.1);
      b.update(in);
    }
    return b.target().yaw;
  };
  const double to_mate = std::atan2(0.5 - by, 0.5 - bx);  // -1.78 rad
  const double inside = 0.5 * f.goal.inner_width - 2.0 * f.ball.radius;
  const double to_line = f.halfLength() - bx;
  const double at_goal =
      0.5 * (std::atan2(inside - by, to_line) + std::atan2(-inside - by, to_line));  // -0.69
  using protocol::gc::SetPlay;
  const auto spl = soccerConfig();
  const auto hsl =
      agents::loadBehaviourConfig(test::sourceDir() / "configs/agents/soccer_hsl_small.yaml");
  agents::BehaviourConfig direct = spl;
  direct.pass_after_restart = agents::BehaviourConfig::PassRule::None;
  EXPECT_NEAR(aim(spl, SetPlay::KickIn, 1, Mate::None), to_mate, 1e-6);
  EXPECT_NEAR(aim(spl, SetPlay::KickIn, 1, Mate::None, true), to_mate, 1e-6);  // attacking -x
  EXPECT_NEAR(aim(spl, SetPlay::GoalKick, 1, Mate::None), to_mate, 1e-6);
  EXPECT_NEAR(aim(spl, SetPlay::CornerKick, 2, Mate::None), to_mate, 1e-6);  // theirs: both teams
  EXPECT_NEAR(aim(spl, SetPlay::KickIn, 1, Mate::KickedSince), at_goal, 1e-6);
  EXPECT_NEAR(aim(spl, SetPlay::KickIn, 1, Mate::KickedBefore), to_mate, 1e-6);
  EXPECT_NEAR(aim(spl, SetPlay::PenaltyKick, 1, Mate::None), at_goal, 1e-6);
  // The HSL's rule counts an opponent's touch: with the goal beyond the farthest pass (4.55 m
  // away, 4 m) a pass back (teammate 3 is behind the ball) does not pay: up the field.
  EXPECT_NEAR(aim(hsl, SetPlay::KickIn, 1, Mate::None), at_goal, 1e-6);
  agents::BehaviourConfig hsl_far = hsl;
  hsl_far.pass_max = 5.0;
  EXPECT_NEAR(aim(hsl_far, SetPlay::KickIn, 1, Mate::None), to_mate, 1e-6);
  EXPECT_NEAR(aim(hsl, SetPlay::KickIn, 2, Mate::None), at_goal, 1e-6);  // theirs: their rule
  EXPECT_NEAR(aim(hsl, SetPlay::GoalKick, 1, Mate::None), at_goal, 1e-6);
  EXPECT_NEAR(aim(direct, SetPlay::KickIn, 1, Mate::None), at_goal, 1e-6);

  // The own kick-in; lined up on the pass at (x, y): the ball before its left foot, facing
  // teammate 3.
  const auto ourKickIn = [] {
    auto g = gameState(3);
    g.kicking_team = 1;
    g.set_play = static_cast<uint8_t>(SetPlay::KickIn);
    g.secondary_time = 30;
    return g;
  };
  const double x = bx - (std::cos(to_mate) * 0.17 - std::sin(to_mate) * 0.05);
  const double y = by - (std::sin(to_mate) * 0.17 + std::cos(to_mate) * 0.05);

  // A robot that kicks after the restart says so at once, and only then.
  {
    agents::SoccerBehaviour b(spl, f, 0, 1, 2, Role::Striker, 1);
    auto g = ourKickIn();
    b.receive(message(3, 0.5, 0.5, Role::Supporter, false, 1.0), 0.2);
    auto p = seeing(x - 0.5, y, to_mate, bx, by, 0.5);  // 0.5 m short of it first
    agents::SoccerBehaviour::Input in;
    in.time = 0.5;
    in.perception = &p;
    in.game = &g;
    const auto decoded = [&](double t) {
      in.time = t;
      const auto out = b.outgoing(in);
      return out ? agents::decodeTeamMessage(*out) : std::nullopt;
    };
    EXPECT_NE(updateSeeing(b, in).kind, MotionRequest::Kind::Kick);
    const auto first = decoded(0.5);
    ASSERT_TRUE(first);
    EXPECT_FALSE(first->kicked);
    EXPECT_FALSE(decoded(0.51));  // paced
    p = seeing(x, y, to_mate, bx, by, 0.6);
    in.time = 0.6;
    EXPECT_EQ(b.update(in).kind, MotionRequest::Kind::Kick);
    const auto news = decoded(0.85);  // 0.35 s after the last: news goes out at once
    ASSERT_TRUE(news);
    EXPECT_TRUE(news->kicked);
    // A set play given again (its time starts over) is a new restart: not kicked since.
    g.secondary_time = 20;
    in.time = 0.9;
    b.update(in);
    g.secondary_time = 30;
    in.time = 1.0;
    b.update(in);
    const auto again = decoded(1.2);
    ASSERT_TRUE(again);
    EXPECT_FALSE(again->kicked);
  }

  // After its own kick (the pass) the kicker passes again under the SPL's rule (two of the team's
  // robots), and plays on under the HSL's (any other robot's touch counts, an opponent's too).
  for (const bool under_hsl : {false, true}) {
    agents::SoccerBehaviour b(under_hsl ? hsl_far : spl, f, 0, 1, 2, Role::Striker, 1);
    auto g = ourKickIn();
    b.receive(message(3, 0.5, 0.5, Role::Supporter, false, 1.0), 0.2);
    auto p = seeing(x, y, to_mate, bx, by, 0.5);
    agents::SoccerBehaviour::Input in;
    in.time = 0.5;
    in.perception = &p;
    in.game = &g;
    ASSERT_EQ(updateSeeing(b, in).kind, MotionRequest::Kind::Kick) << under_hsl;
    b.receive(message(3, 0.5, 0.5, Role::Supporter, false, 1.0), 2.0);  // it did not kick
    p = seeing(x - 0.5, y, to_mate, bx, by, 2.5);  // after the kick, 0.5 m short of the ball
    in.time = 2.5;
    b.update(in);
    EXPECT_NEAR(b.target().yaw, under_hsl ? at_goal : to_mate, 1e-6) << under_hsl;
  }

  // The own kick-off under the HSL's rules, as Playing follows Set: the goal is 4.5 m away,
  // beyond the farthest pass: to the teammate ahead of the ball, or with none, at the goal; with
  // a farther pass, back to the teammate behind it.
  const auto kickOffAim = [&](const agents::BehaviourConfig& cfg, double mate_x) {
    agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Striker, 1);
    b.receive(message(3, mate_x, -1.0, Role::Supporter, false, 1.0), 0.4);
    auto g = gameState(2);  // Set
    g.kicking_team = 1;
    auto p = seeing(-0.3, 0.0, 0.0, 0.0, 0.0, 0.5);
    agents::SoccerBehaviour::Input in;
    in.time = 0.5;
    in.perception = &p;
    in.game = &g;
    updateSeeing(b, in);
    g.state = 3;
    g.secondary_time = 10;
    in.time = 0.6;
    p = seeing(-0.3, 0.0, 0.0, 0.0, 0.0, 0.6);
    b.update(in);
    return b.target().yaw;
  };
  EXPECT_NEAR(kickOffAim(hsl, 1.5), std::atan2(-1.0, 1.5), 1e-6);
  EXPECT_NEAR(kickOffAim(hsl, -1.2), 0.0, 1e-6);
  EXPECT_NEAR(kickOffAim(hsl_far, -1.2), std::atan2(-1.0, -1.2), 1e-6);
  auto g = gameState(3);
  agents::SoccerBehaviour::Input in;
  auto p = seeing(-1.8, 2.3, 0.0, -1.0, 2.9, 0.6);
  in.time = 0.6;
  in.perception = &p;
  in.game = &g;
  agents::SoccerBehaviour deep(spl, f, 0, 1, 2, Role::Striker, 1);
  deep.receive(message(3, -2.2, 1.5, Role::Supporter, false, 1.0), 0.4);  // behind the ball
  g.kicking_team = 1;
  g.set_play = static_cast<uint8_t>(SetPlay::KickIn);
  g.secondary_time = 30;
  updateSeeing(deep, in);
  EXPECT_NEAR(deep.target().yaw,
              0.5 * (std::atan2(inside - 2.9, 5.5) + std::atan2(-inside - 2.9, 5.5)), 1e-6);
}

TEST(SoccerBehaviour, TheNearestFieldPlayerStrikesTheOthersDefendAndSupport) {
  const auto cfg = soccerConfig();
  const auto f = field();
  // Player 3 of team 0 at (-1, 0), the ball at (0, 0); teammates 2 (nearer) and 4 (farther).
  agents::SoccerBehaviour b(cfg, f, 0, 1, 3, Role::Auto, 1);
  const auto game = gameState(3);
  b.receive(mate(2, -0.4, 0.0, 0.4), 0.0);
  b.receive(mate(4, -3.0, 1.0, 3.2), 0.0);
  auto p = seeing(-1.0, 0.0, 0.0, 0.0, 0.0, 0.01);
  agents::SoccerBehaviour::Input in;
  in.time = 0.01;
  in.perception = &p;
  in.game = &game;
  b.update(in);
  EXPECT_EQ(b.role(), Role::Supporter);  // 2 strikes; 4 is nearest the own goal: defender
  // Player 2 falls behind: now player 3 is the nearest.
  b.receive(mate(2, -0.4, 0.0, 2.4), 0.5);
  in.time = 0.5;
  p = seeing(-1.0, 0.0, 0.0, 0.0, 0.0, 0.5);
  b.update(in);
  EXPECT_EQ(b.role(), Role::Striker);
  // Player 1 is the goalkeeper whatever the distances.
  agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, Role::Auto, 1);
  keeper.update(in);
  EXPECT_EQ(keeper.role(), Role::Goalkeeper);
}

TEST(SoccerBehaviour, TheSupporterKeepsItsSideOfTheBallAndOutOfTheDefence) {
  const auto cfg = soccerConfig();
  const auto f = field();  // SPL: 4.5 m half-length, 3 m half-width
  const auto game = gameState(3);
  // Player 3 supports: 2 is next to the ball (strikes), 4 stands deepest (defends).
  // (Positions travel as floats in the perception: targets within 1e-6 m.)
  const auto supporterTarget = [&](double x, double y, double bx, double by) {
    agents::SoccerBehaviour b(cfg, f, 0, 1, 3, Role::Auto, 1);
    b.receive(mate(2, bx - 0.3, by, 0.3), 0.0);
    b.receive(mate(4, -4.0, 0.0, 9.0), 0.0);
    auto p = seeing(x, y, 0.0, bx, by, 0.01);
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    updateSeeing(b, in);
    EXPECT_EQ(b.role(), Role::Supporter);
    return b.target();
  };
  // Right of the ball, it stays right of it (it used to cross to the field's middle,
  // through the striker's path).
  auto t = supporterTarget(-1.0, -1.0, 0.0, -0.3);
  EXPECT_NEAR(t.x, -1.2, 1e-6);
  EXPECT_NEAR(t.y, -1.5, 1e-6);
  t = supporterTarget(-1.0, 0.5, 0.0, -0.3);
  EXPECT_NEAR(t.y, 0.9, 1e-6);
  // Where the touchline leaves no room on its side (0.4 m inside it), the other side.
  t = supporterTarget(-1.0, 2.8, 0.0, 2.3);
  EXPECT_NEAR(t.y, 1.1, 1e-6);
  // The ball near the own goal: not behind it among the defenders and the goalkeeper,
  // but no deeper than supporter_deepest (a share of the half-length).
  t = supporterTarget(-2.0, 1.5, -3.6, 0.5);
  EXPECT_NEAR(t.x, cfg.supporter_deepest * f.halfLength(), 1e-6);
  EXPECT_LT(t.x, -1.0);
  EXPECT_NEAR(t.y, 1.7, 1e-6);
}

TEST(SoccerBehaviour, TheBallInTheOwnGoalAreaIsTheGoalkeepers) {
  const auto cfg = soccerConfig();
  const auto f = field();  // SPL: goal area 0.6 m deep from x = -4.5, 2.2 m wide
  const auto game = gameState(3);
  // Player 2 strikes (3 is far away); the ball lies in the own goal area.
  const auto strikerTarget = [&](std::optional<bool> keeper_fallen, double self_y = 0.5,
                                 double ball_y = 0.3) {
    agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Auto, 1);
    b.receive(mate(3, 2.0, 0.0, 9.0), 0.0);
    if (keeper_fallen) {
      agents::TeamMessageData d;
      d.player = 1;
      d.x = -4.2;
      d.fallen = *keeper_fallen;
      b.receive(agents::TeamMessageIn{.from_player = 1, .data = agents::encodeTeamMessage(d)}, 0.0);
    }
    auto p = seeing(-3.2, self_y, M_PI, -4.2, ball_y, 0.01);
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    updateSeeing(b, in);
    EXPECT_EQ(b.role(), Role::Striker);
    return b.target();
  };
  // The goalkeeper plays: the striker waits outside the area (avoid_near in front of it),
  // facing the ball, instead of going round the ball between it and the goal line; keeper_lane
  // beside the keeper's clearance (the line from the ball to the opponent goal at (4.5, 0)), on
  // its own side of it, or on the other where its own would be beyond the area's width.
  const double wait_x = -3.9 + cfg.avoid_near;
  const auto lane = [&](double ball_y) { return ball_y * (4.5 - wait_x) / (4.5 + 4.2); };
  ASSERT_GT(cfg.keeper_lane, 0.3);
  auto t = strikerTarget(false);
  EXPECT_NEAR(t.x, wait_x, 1e-6);
  EXPECT_NEAR(t.y, lane(0.3) + cfg.keeper_lane, 1e-6);
  t = strikerTarget(false, -0.5);
  EXPECT_NEAR(t.x, wait_x, 1e-6);
  EXPECT_NEAR(t.y, lane(0.3) - cfg.keeper_lane, 1e-6);
  t = strikerTarget(false, 1.0, 0.9);  // its own side: 1.4 m out, beyond the area's 1.1
  EXPECT_NEAR(t.y, lane(0.9) - cfg.keeper_lane, 1e-6);
  // No goalkeeper heard from, or a fallen one: the striker plays the ball itself, from
  // behind it.
  for (const auto keeper : {std::optional<bool>{}, std::optional<bool>{true}}) {
    t = strikerTarget(keeper);
    EXPECT_LT(t.x, -4.2);
  }
  // The goalkeeper clears a slow ball anywhere in the goal area, also further than 1 m
  // (there it used to keep to its line).
  const auto keeperTarget = [&](double bx) {
    agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, Role::Auto, 1);
    auto p = seeing(-4.15, -0.1, 0.0, bx, 1.0, 0.01);  // the ball 1.1 m or more away
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    updateSeeing(keeper, in);
    EXPECT_EQ(keeper.role(), Role::Goalkeeper);
    return keeper.target();
  };
  const double line = -4.5 + cfg.keeper_line;
  EXPECT_NEAR(keeperTarget(-3.8).x, line, 1e-6);  // just outside the goal area: on its line
  t = keeperTarget(-4.1);                         // inside: to the ball, round it
  EXPECT_LT(t.x, line - 0.1);
  EXPECT_GT(t.y, 0.6);
}

// A ball near the own goal line is cleared at an angle that keeps the place to line up from on
// the field (a K1 goalkeeper walked into its goal behind a ball on its line and turned round in
// there for 25 s), to the side whose place is nearer, kept while the sightings move about.
TEST(SoccerBehaviour, ABallOnTheOwnGoalLineIsClearedFromTheField) {
  auto cfg = soccerConfig();
  EXPECT_EQ(cfg.clear_max_angle, 0.0);        // the Nao's: off
  cfg.clear_max_angle = 75.0 * M_PI / 180.0;  // the K1's
  const auto f = field();                     // SPL: the goal line at x = -4.5
  const auto game = gameState(3);
  const double bx = -4.46, by = 0.1;  // 4 cm before the line
  const auto place = [&](double yaw_sign, double robot_y) {
    agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, Role::Auto, 1);
    auto p = seeing(-4.1, robot_y, 0.0, bx, by, 0.01);
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    updateSeeing(keeper, in);
    EXPECT_EQ(keeper.role(), Role::Goalkeeper);
    const auto t = keeper.target();
    // On the line at most (at 75 degrees, the most, the place is 9 cm behind the ball), not in
    // the goal; on the robot's side.
    EXPECT_GT(t.x, -4.5 - 0.06) << robot_y;
    EXPECT_NEAR(t.yaw, yaw_sign * 75.0 * M_PI / 180.0, 1e-6) << robot_y;
    return keeper;
  };
  place(-1.0, 0.6);  // left of the ball: kicks it to the right
  place(1.0, -0.4);  // right of it: to the left
  // Kept while the robot's sightings put the ball a little either side of it; turned when the
  // other place is 0.3 m nearer.
  auto keeper = place(-1.0, 0.3);
  for (const auto& [robot_y, yaw_sign] :
       std::vector<std::pair<double, double>>{{0.05, -1.0}, {0.15, -1.0}, {-0.25, 1.0}}) {
    auto p = seeing(-4.1, robot_y, 0.0, bx, by, 0.1);
    agents::SoccerBehaviour::Input in{.time = 0.1, .perception = &p, .game = &game};
    keeper.update(in);
    EXPECT_NEAR(keeper.target().yaw, yaw_sign * 75.0 * M_PI / 180.0, 1e-6) << robot_y;
  }
}

// A walk does not take a robot into a goal or against its posts and nets (goal_clearance); one
// in a goal walks out through the mouth. Robots walked into their own goal, stepping past a
// teammate or after a ball beside a post, and fell against the net (K1 5 v 5 seeds 9 and 19).
TEST(SoccerBehaviour, WalksKeepOutOfTheGoals) {
  auto cfg = soccerConfig();
  const auto f = field();  // SPL: goal line at x = -4.5, posts' centres at y = +-0.8, 0.5 m deep
  const auto game = gameState(3);
  ASSERT_GT(cfg.goal_clearance, 0.1);
  // The striker at (x, y, yaw) with the ball at (bx, by): its walk in the field frame.
  const auto walk = [&](double x, double y, double yaw, double bx, double by) {
    agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Striker, 1);
    auto p = seeing(x, y, yaw, bx, by, 0.01);
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    const MotionRequest r = updateSeeing(b, in);
    EXPECT_EQ(r.kind, MotionRequest::Kind::Walk);
    const double c = std::cos(yaw), s = std::sin(yaw);
    return std::pair{r.forward * c - r.left * s, r.forward * s + r.left * c};
  };
  // On its own goal line, facing into the goal, a ball in there: the place behind the ball lies
  // deeper in. goal_clearance 0 lets it walk in; with it, no further than 0.1 m past the line.
  const double yaw = M_PI;
  cfg.goal_clearance = 0.0;
  const double free = walk(-4.5, 0.0, yaw, -4.8, 0.0).first;
  ASSERT_LT(free, -0.1);
  cfg.goal_clearance = 0.25;
  EXPECT_NEAR(walk(-4.5, 0.0, yaw, -4.8, 0.0).first, free, 1e-9);  // up to the line: as planned
  EXPECT_NEAR(walk(-4.61, 0.0, yaw, -4.8, 0.0).first, 0.0, 1e-6);
  // Further in: out through the mouth, backwards, facing the back net; also turned diagonally
  // into it, where clamping forward and sideways speed each on its own turned the walk back in.
  EXPECT_GT(walk(-4.8, 0.0, yaw, -4.9, 0.0).first, 0.05);
  EXPECT_GT(walk(-4.8, 0.0, 0.75 * M_PI, -4.95, 0.3).first, 0.02);
  // Behind the back net (0.5 m deep), walking at the field: not into the net.
  EXPECT_NEAR(walk(-5.1, 0.0, 0.0, -3.0, 0.0).first, 0.0, 1e-6);
  // In front of a post, 0.2 m off it, walking at it: not a step nearer.
  EXPECT_GE(walk(-4.3, 0.8, yaw, -4.8, 0.8).first, -1e-6);
  // Beside the goal behind its line, 0.15 m off the side net, walking across at it.
  EXPECT_GE(walk(-4.8, 0.95, -M_PI / 2, -4.8, 0.0).second, -1e-6);
  // The same at the opponents' goal.
  EXPECT_NEAR(walk(4.61, 0.0, 0.0, 4.8, 0.0).first, 0.0, 1e-6);
  // Far from the goals the walk is left as planned, bit for bit.
  cfg.goal_clearance = 0.0;
  const auto open = walk(-2.0, 0.5, 0.3, 0.0, 0.0);
  cfg.goal_clearance = 0.25;
  EXPECT_EQ(walk(-2.0, 0.5, 0.3, 0.0, 0.0), open);
}

// A ball on the own goal line beside a post is cleared from the side of it outside the goal:
// the place behind it on the other side lay within the goal's width, behind the line, and a K1
// goalkeeper walked into the goal for it (K1 5 v 5 seed 9).
TEST(SoccerBehaviour, ABallOnTheLineBesideThePostIsClearedFromOutsideTheGoal) {
  auto cfg = soccerConfig();
  cfg.clear_max_angle = 75.0 * M_PI / 180.0;  // the K1's
  const auto f = field();
  const auto game = gameState(3);
  const double bx = -4.52, by = 1.05;  // on the line, 0.2 m beside the post's centre
  for (const double robot_y : {0.3, 1.6}) {
    agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, Role::Auto, 1);
    auto p = seeing(-4.1, robot_y, 0.0, bx, by, 0.01);
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    updateSeeing(keeper, in);
    ASSERT_EQ(keeper.role(), Role::Goalkeeper);
    // Kicked to the right (-75 degrees) from the place on the left, outside the goal; from y
    // 0.3 the place inside (y 0.71) is the nearer one.
    EXPECT_NEAR(keeper.target().yaw, -75.0 * M_PI / 180.0, 1e-6) << robot_y;
  }
}

// On its line the goalkeeper steps sideways to its place, facing the field, across its whole
// goal; it used to turn towards any place more than 0.5 m away and walk there, its back to the
// ball, and a K1 fell sideways turning back and forth. Off its line it turns and walks.
TEST(SoccerBehaviour, TheGoalkeeperStepsSidewaysAlongItsLine) {
  const auto cfg = soccerConfig();
  // SPL: the goal 1.5 m wide, the keeper's places within 0.6 m of its middle.
  const auto f = field();
  const auto game = gameState(3);
  const double line = -f.halfLength() + cfg.keeper_line;
  const auto walk = [&](double x, double y, double ball_y) {
    agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, Role::Auto, 1);
    auto p = seeing(x, y, 0.0, -1.0, ball_y, 0.01);
    agents::SoccerBehaviour::Input in{.time = 0.02, .perception = &p, .game = &game};
    const MotionRequest r = updateSeeing(keeper, in);
    EXPECT_EQ(keeper.role(), Role::Goalkeeper);
    return std::pair{r, keeper.target()};
  };
  // From one post to the other's place: 1.2 m to its left.
  auto [r, t] = walk(line, -0.6, 3.0);
  EXPECT_NEAR(t.y, 0.6, 1e-6);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Walk);
  EXPECT_NEAR(r.left, cfg.max_side, 1e-6);
  EXPECT_NEAR(r.turn, 0.0, 1e-6);
  // 2 m in front of its line (back from clearing the ball): it turns to walk back.
  std::tie(r, t) = walk(line + 2.0, 0.0, 0.0);
  EXPECT_NEAR(std::abs(r.turn), cfg.max_turn, 1e-6);
}

TEST(SoccerBehaviour, TwoRobotsClaimingTheStrikerRoleSettleOnTheSameOne) {
  const auto cfg = soccerConfig();
  const auto f = field();
  const auto game = gameState(3);
  // Players 2 and 3 about as far from the ball (0.51 and 0.52 m), within the
  // striker's hysteresis of each other; neither has heard from the other, so
  // both strike.
  agents::SoccerBehaviour two(cfg, f, 0, 1, 2, Role::Auto, 1),
      three(cfg, f, 0, 1, 3, Role::Auto, 1);
  auto p2 = seeing(-0.5, 0.1, 0.0, 0.0, 0.0, 0.01), p3 = seeing(-0.5, -0.15, 0.0, 0.0, 0.0, 0.01);
  agents::SoccerBehaviour::Input in2, in3;
  in2.time = in3.time = 0.01;
  in2.perception = &p2;
  in3.perception = &p3;
  in2.game = in3.game = &game;
  two.update(in2);
  three.update(in3);
  ASSERT_EQ(two.role(), Role::Striker);
  ASSERT_EQ(three.role(), Role::Striker);
  // Each hears the other claim the role: the nearer keeps it, the other gives it up.
  const auto from = [](int player, const std::optional<std::vector<uint8_t>>& bytes) {
    agents::TeamMessageIn m;
    m.from_player = player;
    m.data = bytes.value();
    return m;
  };
  const auto m2 = two.outgoing(in2), m3 = three.outgoing(in3);
  two.receive(from(3, m3), 0.02);
  three.receive(from(2, m2), 0.02);
  in2.time = in3.time = 0.02;
  two.update(in2);
  three.update(in3);
  EXPECT_EQ(two.role(), Role::Striker);
  EXPECT_NE(three.role(), Role::Striker);
}

TEST(SoccerBehaviour, TakingOrGivingUpTheStrikerRoleIsSentAtOnce) {
  const auto cfg = soccerConfig();
  const auto f = field();
  const auto game = gameState(3);  // a full game's budget: a message every 5 s per robot
  agents::SoccerBehaviour b(cfg, f, 0, 1, 3, Role::Auto, 1);
  auto p = seeing(-1.0, 0.0, 0.0, 0.0, 0.0, 0.01);
  agents::SoccerBehaviour::Input in;
  in.perception = &p;
  in.game = &game;
  const auto at = [&](double t) {
    in.time = t;
    p.sim_time = t;
    p.ball.last_seen = t;
    updateSeeing(b, in);
    return b.outgoing(in);
  };
  // Alone, it strikes, and says so.
  const auto first = at(0.01);
  ASSERT_TRUE(first);
  EXPECT_EQ(agents::decodeTeamMessage(*first)->role, Role::Striker);
  // Nothing new: the next message waits for the budget's pace.
  EXPECT_FALSE(at(0.5));
  // Player 2 is nearer the ball: it gives the role up, and says so at once ...
  b.receive(mate(2, -0.2, 0.0, 0.2), 0.6);
  const auto news = at(0.7);
  ASSERT_TRUE(news);
  EXPECT_NE(agents::decodeTeamMessage(*news)->role, Role::Striker);
  // ... and then waits for the pace again.
  EXPECT_FALSE(at(1.5));
  EXPECT_TRUE(at(5.8));
}

TEST(SoccerBehaviour, APenalisedTeammateIsLeftOutOfTheRoles) {
  const auto cfg = soccerConfig();
  const auto f = field();
  // Player 2 said it strikes, 0.2 m from the ball; player 3 is 1 m from it.
  agents::TeamMessageIn claim = mate(2, -0.2, 0.0, 0.2);
  {
    agents::TeamMessageData d = *agents::decodeTeamMessage(claim.data);
    d.role = Role::Striker;
    claim.data = agents::encodeTeamMessage(d);
  }
  const auto roleOfThree = [&](bool two_penalised) {
    auto game = gameState(3);
    if (two_penalised) game.teams[0].players[1].penalty = 2;  // pushing
    agents::SoccerBehaviour b(cfg, f, 0, 1, 3, Role::Auto, 1);
    b.receive(claim, 0.0);
    const auto p = seeing(-1.0, 0.0, 0.0, 0.0, 0.0, 0.5);
    agents::SoccerBehaviour::Input in{.time = 0.5, .perception = &p, .game = &game};
    updateSeeing(b, in);
    return b.role();
  };
  EXPECT_NE(roleOfThree(false), Role::Striker);
  // Taken out by the referee, player 2 sends nothing more; its claim no longer counts.
  EXPECT_EQ(roleOfThree(true), Role::Striker);
}

// Four field players, two of whom defend: each defender computes its own place; the
// two must agree on who stands left (+y) wherever they stand, even when each has the
// other's position from an old message.
struct FieldPlayer {
  int number;
  double x, y;
};
static void expectDefendersSideBySide(const std::vector<FieldPlayer>& team, int striker,
                                      int left_number, int right_number) {
  const auto cfg = soccerConfig();
  const auto f = field();
  const auto game = gameState(3);
  // (Deeper than x = -2.9 the defenders stand wide: DefendersStandWideOfADeepBall.)
  for (const Vec3& ball : {Vec3(1.0, 1.0, 0), Vec3(-2.0, 2.5, 0), Vec3(-2.6, -1.5, 0)}) {
    std::map<int, agents::Pose2> targets;
    for (const FieldPlayer& me : team) {
      if (me.number != left_number && me.number != right_number) continue;
      agents::SoccerBehaviour b(cfg, f, 0, 1, me.number, Role::Auto, 1);
      for (const FieldPlayer& other : team)
        if (other.number != me.number)
          b.receive(mate(other.number, other.x, other.y,
                         std::hypot(ball.x() - other.x, ball.y() - other.y) -
                             (other.number == striker ? 5.0 : 0.0)),
                    0.0);
      auto p = seeing(me.x, me.y, 0.0, ball.x(), ball.y(), 0.01);
      agents::SoccerBehaviour::Input in;
      in.time = 0.01;
      in.perception = &p;
      in.game = &game;
      updateSeeing(b, in);
      ASSERT_EQ(b.role(), Role::Defender) << "player " << me.number;
      targets[me.number] = b.target();
    }
    const agents::Pose2 left = targets[left_number], right = targets[right_number];
    const double apart = std::hypot(left.x - right.x, left.y - right.y);
    std::printf(
        "ball (%.1f, %.1f): defenders %d at (%.2f, %.2f) and %d at (%.2f, %.2f), %.2f m apart\n",
        ball.x(), ball.y(), left_number, left.x, left.y, right_number, right.x, right.y, apart);
    // Apart by the spacing (less only where the field's edge or the goal line stops one) ...
    EXPECT_GT(apart, 0.7 * cfg.defender_spacing);
    EXPECT_LT(apart, cfg.defender_spacing + 1e-6);
    // ... and the left one on the left of the line from the own goal to the ball.
    const double goal_x = -f.halfLength();  // the own goal's centre, y 0
    const auto side = [&](const agents::Pose2& t) {
      return (ball.x() - goal_x) * t.y - ball.y() * (t.x - goal_x);
    };
    EXPECT_GT(side(left), 0.0);
    EXPECT_LT(side(right), 0.0);
  }
}

TEST(SoccerBehaviour, TwoDefendersStandSideBySideAcrossTheLineToTheirGoal) {
  // 2 next to the ball strikes, 4 furthest up supports, 3 and 5 defend: 3's ready
  // position is further left than 5's, so 3 takes the left place (5 stands on the left here).
  expectDefendersSideBySide({{2, 0.5, 1.0}, {3, -3.0, -0.6}, {4, -0.5, -1.5}, {5, -2.8, 0.8}}, 2, 3,
                            5);
}

TEST(SoccerBehaviour, DefendersKeepTheSidesOfTheirReadyPositions) {
  // 2 and 3 defend, 4 strikes, 5 supports. 2 starts on the right (ready y -0.35 of the
  // half-width), 3 on the left (+0.35): by player number 2 took the left place and the
  // two crossed and met head-on after every kick-off.
  expectDefendersSideBySide({{2, -3.0, -0.8}, {3, -3.0, 0.8}, {4, 0.5, 1.0}, {5, -0.5, -1.5}}, 4, 3,
                            2);
}

// A ball nearer the goal line than the defenders may stand in front of it (their place
// defender_goal_distance from the line and 0.8 m in front of the ball) is the goalkeeper's and
// the waiting striker's: the defenders stand on both sides of the goal area, avoid_near beside
// it, the left one on the left, until the ball is 0.3 m further out again. Across the ball-goal
// line they stood among the robots round the ball (K1 5 v 5: 42 of 70 falls came with the ball
// within 2 m of a goal line).
TEST(SoccerBehaviour, DefendersStandWideOfADeepBall) {
  const auto cfg = soccerConfig();
  const auto f = field();  // SPL: goal area 0.6 m deep, 2.2 m wide
  const auto game = gameState(3);
  const double deepest = -f.halfLength() + cfg.defender_goal_distance;
  const double wide = 0.5 * f.goal_area->width + cfg.avoid_near;
  // 2 strikes, 3 (left at kick-off) and 5 defend, 4 supports.
  const std::vector<FieldPlayer> team{
      {2, -3.6, 0.0}, {3, -3.2, 0.6}, {4, -1.0, -1.5}, {5, -3.2, -0.6}};
  // (Plain names, not a structured binding: clang before 16 cannot capture one in a lambda.)
  for (const std::pair<int, double>& defender : {std::pair{3, wide}, std::pair{5, -wide}}) {
    const int number = defender.first;
    const double y = defender.second;
    agents::SoccerBehaviour b(cfg, f, 0, 1, number, Role::Auto, 1);
    const auto at = [&](double ball_x, double ball_y, double time) {
      for (const FieldPlayer& other : team)
        if (other.number != number)
          b.receive(mate(other.number, other.x, other.y,
                         std::hypot(ball_x - other.x, ball_y - other.y) -
                             (other.number == 2 ? 5.0 : 0.0)),
                    time);
      const FieldPlayer& me = *std::find_if(
          team.begin(), team.end(), [&](const FieldPlayer& p) { return p.number == number; });
      auto p = seeing(me.x, me.y, 0.0, ball_x, ball_y, time);
      agents::SoccerBehaviour::Input in{.time = time, .perception = &p, .game = &game};
      updateSeeing(b, in);
      EXPECT_EQ(b.role(), Role::Defender) << "player " << number;
      return b.target();
    };
    // In the goal area, and just deeper than the defenders' place allows: wide.
    for (const double bx : {-4.2, deepest + 0.75}) {
      const agents::Pose2 t = at(bx, 0.3, bx == -4.2 ? 0.1 : 0.2);
      EXPECT_NEAR(t.x, deepest, 1e-6) << "player " << number << ", ball x " << bx;
      EXPECT_NEAR(t.y, y, 1e-6) << "player " << number << ", ball x " << bx;
    }
    // Out again by less than 0.3 m: still wide; further: across the line to the goal.
    EXPECT_NEAR(at(deepest + 1.0, 0.3, 0.3).y, y, 1e-6) << "player " << number;
    EXPECT_LT(std::abs(at(deepest + 1.2, 0.3, 0.4).y), wide - 0.3) << "player " << number;
  }
}

TEST(SoccerBehaviour, ObeysTheGameState) {
  const auto cfg = soccerConfig();
  const auto f = field();
  agents::SoccerBehaviour b(cfg, f, 0, 1, 4, Role::Striker, 1);
  auto p = seeing(-3.0, 1.0, 0.0, 0.0, 0.0, 0.0);
  agents::SoccerBehaviour::Input in;
  in.perception = &p;
  for (int s : {0, 2, 5}) {  // Initial, Set, Standby: stand
    const auto g = gameState(s);
    in.game = &g;
    EXPECT_EQ(b.update(in).kind, MotionRequest::Kind::Stand) << s;
  }
  // Finished: sits down, except between the shoot-out's kicks.
  auto finished = gameState(4);
  in.game = &finished;
  EXPECT_EQ(b.update(in).kind, MotionRequest::Kind::Sit);
  finished.game_phase = 1;  // penalty shoot-out
  EXPECT_EQ(b.update(in).kind, MotionRequest::Kind::Stand);
  // The K1's config: it stands when the half is over.
  agents::SoccerBehaviour k1(
      agents::loadBehaviourConfig(test::sourceDir() / "configs/agents/soccer_k1.yaml"), f, 0, 1, 4,
      Role::Striker, 1);
  finished.game_phase = 0;
  EXPECT_EQ(k1.update(in).kind, MotionRequest::Kind::Stand);
  EXPECT_EQ(b.update(in).kind, MotionRequest::Kind::Sit);
  // Ready: walks to its kick-off place (player 4: (-0.35, -0.55) of the half-sizes).
  auto g = gameState(1);
  in.game = &g;
  const MotionRequest r = b.update(in);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Walk);
  EXPECT_LT(r.turn, 0.0);  // the place is to its right
  // Penalised: stands, and its motion restarts (the flag the earlier states
  // raised is taken first, so only the penalty can raise it again).
  b.takeMotionRestart();
  g = gameState(3);
  g.teams[0].players[3].penalty = 1;
  EXPECT_EQ(b.update(in).kind, MotionRequest::Kind::Stand);
  EXPECT_TRUE(b.takeMotionRestart());  // it will be moved
  // In the second half (the team on the right), it attacks -x: a ball
  // behind it (at x -4) is in front of the goal it now attacks.
  g = gameState(3, 2);
  p = seeing(-3.0, 0.0, M_PI, -3.5, 0.0, 1.0);
  in.time = 1.0;
  const MotionRequest r2 = b.update(in);
  EXPECT_EQ(r2.kind, MotionRequest::Kind::Walk);
  EXPECT_GT(r2.forward, 0.0);  // towards the ball, no turning round
}

TEST(SoccerBehaviour, TheStrikerKicksWhenTheBallIsInFrontOfAFootAndAimedAtTheGoal) {
  const auto cfg = soccerConfig();
  const auto f = field();
  agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Striker, 1);
  agents::SoccerBehaviour::Input in;
  // The ball 0.17 m ahead, 0.05 m to the left; the goal straight ahead.
  auto p = seeing(2.0, -0.05, 0.0, 2.17, 0.0, 0.1);
  in.time = 0.1;
  in.perception = &p;
  MotionRequest r = updateSeeing(b, in);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Kick);
  EXPECT_EQ(r.kick_foot, agents::Leg::Left);
  // Turned 0.5 rad away from the goal: no kick, it turns back.
  agents::SoccerBehaviour c(cfg, f, 0, 1, 2, Role::Striker, 1);
  p = seeing(2.0, -0.05, 0.5, 2.0 + 0.17 * std::cos(0.5) - 0.05 * std::sin(0.5),
             -0.05 + 0.17 * std::sin(0.5) + 0.05 * std::cos(0.5), 0.1);
  r = updateSeeing(c, in);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Walk);
  EXPECT_LT(r.turn, 0.0);
  // Head: towards the ball it sees.
  EXPECT_NEAR(r.head_yaw, std::atan2(0.05, 0.17), 0.01);
}

// The ball is lined up against the feet, not the torso: with the torso swayed 5 cm right of
// its feet, a ball seen 5 cm left of the torso lies between the feet (no kick: it steps
// sideways to bring a foot behind it), one seen 10 cm left lies in front of the left foot.
TEST(SoccerBehaviour, TheStrikerLinesTheBallUpAgainstTheFeetNotTheSwayingTorso) {
  const auto cfg = soccerConfig();  // kick_ball: 0.17 m ahead, 0.05 m beside the feet's middle
  const auto f = field();
  agents::SoccerBehaviour::Input in;
  in.time = 0.1;
  in.feet = {0.0, 0.05};
  agents::SoccerBehaviour between(cfg, f, 0, 1, 2, Role::Striker, 1);
  auto p = seeing(2.0, -0.05, 0.0, 2.17, 0.0, 0.1);
  in.perception = &p;
  MotionRequest r = updateSeeing(between, in);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Walk);
  EXPECT_GT(r.left, 0.04);  // left, to bring its right foot (the first) behind the ball
  agents::SoccerBehaviour in_front(cfg, f, 0, 1, 2, Role::Striker, 1);
  p = seeing(2.0, -0.1, 0.0, 2.17, 0.0, 0.1);
  r = updateSeeing(in_front, in);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Kick);
  EXPECT_EQ(r.kick_foot, agents::Leg::Left);
}

// The kicking foot changes only once the ball is half the foot's offset past the middle: the
// torso's sway moves a ball near the middle back and forth, and a foot that changed as the ball
// crossed it had the robot step left and right under the ball without kicking.
TEST(SoccerBehaviour, TheKickingFootChangesOnlyOnceTheBallIsWellOverToTheOtherSide) {
  const auto cfg = soccerConfig();  // kick_ball 0.05 m sideways: the foot changes beyond 0.025
  agents::Leg foot = agents::Leg::Right;
  const auto lineUp = [&](double ball_y) {
    return agents::lineUpForKick(cfg, 0.17, ball_y, 0.0, 0.15, foot);
  };
  EXPECT_GT(lineUp(0.02).left, 0.04);  // the right foot kept: the ball 0.07 m left of it
  EXPECT_EQ(foot, agents::Leg::Right);
  lineUp(-0.02);
  EXPECT_EQ(foot, agents::Leg::Right);
  const MotionRequest kick = lineUp(0.03);  // the left foot now, the ball 2 cm inside it
  EXPECT_EQ(foot, agents::Leg::Left);
  EXPECT_EQ(kick.kind, MotionRequest::Kind::Kick);
  EXPECT_EQ(kick.kick_foot, agents::Leg::Left);
  lineUp(0.0);
  lineUp(-0.02);
  EXPECT_EQ(foot, agents::Leg::Left);
  lineUp(-0.03);
  EXPECT_EQ(foot, agents::Leg::Right);
}

// Near the goal line in front of the goal the striker aims into the middle of the angle the
// posts leave open (a ball's width inside each), not at the goal's middle, which lies almost
// along the line from there. The ball 0.15 m before the line, 0.5 m left of the middle, on the
// SPL field (posts 1.5 m apart, a 0.1 m ball): the open angle's middle is -0.328 rad, the
// goal's middle -1.279. The striker facing -0.328 with the ball before its left foot kicks.
TEST(SoccerBehaviour, NearTheGoalLineTheStrikerAimsIntoTheOpenAngle) {
  const auto cfg = soccerConfig();
  const auto f = field();
  const double bx = 4.35, by = 0.5, inside = 0.75 - 0.1;
  const double aim = 0.5 * (std::atan2(inside - by, 4.5 - bx) + std::atan2(-inside - by, 4.5 - bx));
  EXPECT_NEAR(aim, -0.328, 0.001);
  const double c = std::cos(aim), s = std::sin(aim);
  const double x = bx - (c * 0.17 - s * 0.05), y = by - (s * 0.17 + c * 0.05);
  agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Striker, 1);
  agents::SoccerBehaviour::Input in;
  in.time = 0.1;
  auto p = seeing(x, y, aim, bx, by, 0.1);
  in.perception = &p;
  const MotionRequest r = updateSeeing(b, in);
  EXPECT_EQ(r.kind, MotionRequest::Kind::Kick);
  EXPECT_EQ(r.kick_foot, agents::Leg::Left);
}

// The feet's midpoint the motion reads from its encoders and IMU angles is where the feet stand
// under the torso (in the perception's robot frame: below the torso, along its heading), within
// 2 mm, while the torso sways centimetres over them stepping sideways (a Nao and a K1).
TEST(MotionController, TheFeetCentreIsWhereTheFeetStandWhileTheTorsoSways) {
  for (const auto& file : {test::naoH25(), test::boosterK1()}) {
    SCOPED_TRACE(file.filename().string());
    world::Scenario s = test::scenario(1);
    s.robot_model_file = file;
    world::World w(s);
    const robots::RobotModel& model = *w.robot(0).model;
    agents::MotionController mc = agents::loadMotionController(
        model, agents::motionsFolder(test::sourceDir() / "configs/motions", model),
        agents::FallDetectorParameters{});
    std::vector<float> position(model.actuators.size()), stiffness(model.actuators.size());
    MotionRequest walk;
    walk.kind = MotionRequest::Kind::Walk;
    walk.left = 0.05;
    double worst = 0.0, lowest = 1.0, highest = -1.0;
    for (int i = 0; i < 400; ++i) {
      const Eigen::Vector2d read = mc.feetCentre(agents::motionSensors(w.sensorFrame(0)));
      const engine::Pose torso = w.torsoPose(0);
      const Vec3 middle = 0.5 * (w.linkPose(0, model.legs[0].foot_link).translation() +
                                 w.linkPose(0, model.legs[1].foot_link).translation());
      const double yaw = std::atan2(torso.linear()(1, 0), torso.linear()(0, 0));
      const Eigen::Vector2d truth =
          Eigen::Rotation2Dd(-yaw) * (middle - torso.translation()).head<2>();
      if (i >= 100) {  // walking
        worst = std::max(worst, (read - truth).norm());
        lowest = std::min(lowest, truth.y());
        highest = std::max(highest, truth.y());
      }
      controlPeriod(w, mc, walk, position, stiffness);
    }
    EXPECT_TRUE(w.isStanding(0));
    EXPECT_LT(worst, 0.002);            // 0.4 mm on the Nao, 0.1 mm on the K1
    EXPECT_GT(highest - lowest, 0.02);  // the sway the torso frame reads: 3.9 and 8.3 cm
  }
}

// The goalkeeper against a ball rolled at it (perceived every 0.1 s, its
// velocity estimated by the behaviour): it blocks one coming at it in time;
// in the shoot-out it dives, to the ball's side, for one out of the block's
// reach; a slow ball or one going wide is neither blocked nor dived for.
TEST(SoccerBehaviour, TheGoalkeeperBlocksAndInTheShootoutDives) {
  const auto cfg = soccerConfig();
  const auto f = field();
  struct Outcome {
    MotionRequest::Kind kind = MotionRequest::Kind::Walk;
    agents::Leg side = agents::Leg::Left;
    double ball_x = 0.0;  // where the ball was when the keeper acted
  };
  // Ball from (x0, y0) at (vx, vy) m/s; the keeper at (x, 0) facing +x.
  auto roll = [&](Role role, double x, double y0, double vx, double vy, double x0 = -1.5) {
    agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, role, 1);
    Outcome o;
    for (int i = 0; i < 40; ++i) {
      const double t = 0.1 * i, bx = x0 + vx * t, by = y0 + vy * t;
      if (bx < x) break;  // passed it
      auto p = seeing(x, 0.0, 0.0, bx, by, t);
      agents::SoccerBehaviour::Input in;
      in.time = t;
      in.perception = &p;
      const MotionRequest r = keeper.update(in);
      if (r.kind == MotionRequest::Kind::Block || r.kind == MotionRequest::Kind::Dive) {
        o = {r.kind, r.side, bx};
        break;
      }
    }
    return o;
  };
  const double line = -f.halfLength() + cfg.keeper_line;
  const double shootout_line = -f.halfLength() + cfg.shootout_keeper_line;
  // Straight at the keeper at 2 m/s: a block, before the ball is there.
  Outcome o = roll(Role::Goalkeeper, line, 0.1, -2.0, 0.0);
  EXPECT_EQ(o.kind, MotionRequest::Kind::Block);
  EXPECT_GT(o.ball_x - line, 0.3);
  const auto acted = [](const Outcome& x) {
    return x.kind == MotionRequest::Kind::Block || x.kind == MotionRequest::Kind::Dive;
  };
  // 0.6 m to its side: no dive in play (it would end on the ground) ...
  EXPECT_FALSE(acted(roll(Role::Goalkeeper, line, 0.6, -2.0, 0.0)));
  // ... but in the shoot-out: to the left for +y, to the right for -y.
  o = roll(Role::PenaltyGoalkeeper, shootout_line, 0.6, -2.0, 0.0);
  EXPECT_EQ(o.kind, MotionRequest::Kind::Dive);
  EXPECT_EQ(o.side, agents::Leg::Left);
  EXPECT_GT(o.ball_x - shootout_line, 0.5);  // a dive takes longer to reach the ground
  o = roll(Role::PenaltyGoalkeeper, shootout_line, -0.6, -2.0, 0.0);
  EXPECT_EQ(o.kind, MotionRequest::Kind::Dive);
  EXPECT_EQ(o.side, agents::Leg::Right);
  // Slow (0.3 m/s, from 0.5 m: it passes within the block's time), or 1.2 m
  // wide of the keeper: neither. (At 0.6 m/s the same ball is blocked.)
  EXPECT_FALSE(
      acted(roll(Role::PenaltyGoalkeeper, shootout_line, 0.1, -0.3, 0.0, shootout_line + 0.5)));
  EXPECT_EQ(roll(Role::PenaltyGoalkeeper, shootout_line, 0.1, -0.6, 0.0, shootout_line + 0.9).kind,
            MotionRequest::Kind::Block);
  EXPECT_FALSE(acted(roll(Role::PenaltyGoalkeeper, shootout_line, 1.2, -2.0, 0.0)));
}

// A walking robot that sees another robot ahead slows its approach to it and
// steps past it, away from its side; robots further than avoid_far, behind it,
// or met at the ball in play (contested there) change nothing.
TEST(SoccerBehaviour, WalkingRobotsStepPastTheRobotsTheySeeAhead) {
  const auto cfg = soccerConfig();
  const auto f = field();
  // The striker at (-2, 0) facing +x, the ball at (bx, 0): it walks straight at it.
  auto walk = [&](double bx, std::optional<std::pair<double, double>> other, int team = 1) {
    agents::SoccerBehaviour striker(cfg, f, 0, 1, 2, Role::Striker, 1);
    auto p = seeing(-2.0, 0.0, 0.0, bx, 0.0, 0.0);
    if (other) {
      agents::PerceivedIn o;
      o.kind = 2;
      o.team = team;
      o.in_view = true;
      o.last_seen = 0.0;
      o.x = static_cast<float>(other->first);
      o.y = static_cast<float>(other->second);
      p.robots.push_back(o);
    }
    agents::SoccerBehaviour::Input in;
    in.perception = &p;
    return updateSeeing(striker, in);
  };
  const MotionRequest free = walk(1.0, std::nullopt);
  ASSERT_EQ(free.kind, MotionRequest::Kind::Walk);
  ASSERT_GT(free.forward, 0.2);
  // 0.5 m ahead, a little to its left: slower, and a step to the right.
  const MotionRequest near = walk(1.0, std::make_pair(0.5, 0.1));
  EXPECT_LT(near.forward, 0.6 * free.forward);
  EXPECT_LT(near.left, free.left - 0.03);
  // ... a little to its right: a step to the left.
  EXPECT_GT(walk(1.0, std::make_pair(0.5, -0.1)).left, free.left + 0.03);
  // Right up against it (avoid_near): no approach left at all.
  const MotionRequest touching = walk(1.0, std::make_pair(cfg.avoid_near, 0.0));
  EXPECT_NEAR(touching.forward, 0.0, 1e-9);
  for (const auto& [x, y] : {std::make_pair(1.5, 0.0), std::make_pair(-0.5, 0.0)}) {
    const MotionRequest r = walk(1.0, std::make_pair(x, y));  // far ahead; behind
    EXPECT_DOUBLE_EQ(r.forward, free.forward);
    EXPECT_DOUBLE_EQ(r.left, free.left);
  }
  // At the ball (0.4 m ahead) with an opponent there too: the ball is
  // contested. A teammate nearer the ball is given way to.
  const MotionRequest at_ball = walk(-1.6, std::nullopt);
  const MotionRequest contested = walk(-1.6, std::make_pair(0.45, 0.0));
  EXPECT_DOUBLE_EQ(contested.forward, at_ball.forward);
  EXPECT_DOUBLE_EQ(contested.left, at_ball.left);
  EXPECT_LT(walk(-1.6, std::make_pair(0.38, 0.05), 0).forward, 0.5 * at_ball.forward);
  const MotionRequest teammate_further = walk(-1.6, std::make_pair(0.5, 0.6), 0);
  EXPECT_DOUBLE_EQ(teammate_further.forward, at_ball.forward);  // further from the ball
}

// A robot that leaves the cameras' view (the head turned to the ball) is still
// stepped past where it was seen on the field, from wherever the walker is now,
// for obstacle_memory; then it is forgotten.
TEST(SoccerBehaviour, RobotsOutOfViewAreRememberedWhereTheyWereSeen) {
  const auto cfg = soccerConfig();
  const auto f = field();
  ASSERT_GT(cfg.obstacle_memory, 1.0);
  agents::SoccerBehaviour with(cfg, f, 0, 1, 2, Role::Striker, 1);
  agents::SoccerBehaviour without(cfg, f, 0, 1, 2, Role::Striker, 1);
  // t = 0: at (-2, 0) facing +x, an opponent seen 0.6 m ahead, 0.1 m to the left:
  // on the field at (-1.4, 0.1). The ball at (1, 0).
  auto frame = [&](double t, double x, double yaw, bool robot_in_view) {
    auto p = seeing(x, 0.0, yaw, 1.0, 0.0, t);
    agents::PerceivedIn o;
    o.kind = 2;
    o.team = 1;
    o.in_view = robot_in_view;
    o.last_seen = 0.0;
    o.x = 0.6f;  // out of view: the last sighting's numbers, from where it was taken
    o.y = 0.1f;
    p.robots.push_back(o);
    return p;
  };
  auto step = [&](double t, double x, double yaw, bool robot_in_view) {
    agents::PerceptionIn p = frame(t, x, yaw, robot_in_view);
    agents::PerceptionIn empty = p;
    empty.robots.clear();
    agents::SoccerBehaviour::Input in;
    in.time = t;
    in.perception = &p;
    const MotionRequest r = updateSeeing(with, in);
    in.perception = &empty;
    return std::make_pair(r, updateSeeing(without, in));
  };
  const auto [seen, free0] = step(0.0, -2.0, 0.0, true);
  ASSERT_EQ(free0.kind, MotionRequest::Kind::Walk);
  EXPECT_LT(seen.forward, free0.forward - 0.05);
  // t = 1: out of view, the walker 0.15 m on and turned 0.4 rad to the left: the
  // robot is now 0.45 m ahead, 0.08 m to its right (its stale numbers would say
  // 0.6 m ahead, 0.1 m to the left). Hardly any approach left, a step to the left.
  const auto [remembered, free1] = step(1.0, -1.85, 0.4, false);
  ASSERT_EQ(free1.kind, MotionRequest::Kind::Walk);
  EXPECT_LT(remembered.forward, 0.5 * free1.forward);
  EXPECT_GT(remembered.left, free1.left + 0.03);
  // After obstacle_memory it is forgotten.
  const auto [forgotten, free2] = step(cfg.obstacle_memory + 0.1, -1.85, 0.4, false);
  EXPECT_DOUBLE_EQ(forgotten.forward, free2.forward);
  EXPECT_DOUBLE_EQ(forgotten.left, free2.left);
}

// A false ball (the realistic profile's: one frame, somewhere ahead) is not taken for the ball,
// nor kept as the last sighting once out of view: the robot would walk after it, and it stays
// ahead of a robot walking after it. Nor are two in a row. A ball seen ball_new_sightings
// times in a row elsewhere is the ball moved.
TEST(SoccerBehaviour, AFalseBallSeenForOneFrameIsNotChased) {
  const auto cfg = soccerConfig();
  const auto f = field();
  agents::SoccerBehaviour b(cfg, f, 0, 1, 2, Role::Striker, 1);
  const auto game = gameState(3);
  agents::SoccerBehaviour::Input in;
  in.game = &game;
  const auto update = [&](agents::PerceptionIn p, double t) {
    in.time = t;
    in.perception = &p;
    b.update(in);
  };
  // At (-2, 0) facing +x, the ball at (1, 0) seen for 0.1 s, then out of view.
  double t = 0.0;
  for (; t < 0.1; t += 0.01) update(seeing(-2.0, 0.0, 0.0, 1.0, 0.0, t), t);
  const double target_x = b.target().x;
  EXPECT_NEAR(target_x, 1.0 - cfg.approach_distance, 0.05);
  auto unseen = seeing(-2.0, 0.0, 0.0, 1.0, 0.0, t);
  unseen.ball.in_view = false;
  unseen.ball.last_seen = 0.09f;
  update(unseen, t);
  // A false ball at field (bx, by), `after` s from the last update, for one frame; then none
  // for 0.5 s, the perception's memory holding it (its last sighting).
  const auto falseBall = [&](double after, double bx, double by) {
    t += after;
    auto ghost = seeing(-2.0, 0.0, 0.0, bx, by, t);
    update(ghost, t);
    ghost.ball.in_view = false;
    for (int i = 0; i < 50; ++i) {
      t += 0.01;
      update(ghost, t);
    }
  };
  // One, 1.5 m ahead at (-0.5, 0.2).
  falseBall(0.01, -0.5, 0.2);
  EXPECT_NEAR(b.target().x, target_x, 0.05) << b.status();
  // Two in a row, 0.08 s apart and 0.4 m from each other (a K1 goalkeeper took such a pair for
  // a ball beside its post and walked into the post after it): not taken.
  t += 0.01;
  update(seeing(-2.0, 0.0, 0.0, -1.3, -0.2, t), t);
  falseBall(0.08, -1.0, 0.05);
  EXPECT_NEAR(b.target().x, target_x, 0.05) << b.status();
  // The ball seen ball_new_sightings times in a row at (0, 1): moved while unseen, taken; one
  // sighting fewer is not enough.
  for (int i = 0; i < cfg.ball_new_sightings - 1; ++i) {
    t += 0.01;
    update(seeing(-2.0, 0.0, 0.0, 0.0, 1.0, t), t);
  }
  EXPECT_NEAR(b.target().x, target_x, 0.05) << b.status();
  t += 0.01;
  update(seeing(-2.0, 0.0, 0.0, 0.0, 1.0, t), t);
  EXPECT_GT(b.target().y, 0.5) << b.status();
}

// The shoot-out keeper waits for the kick with the ball on the penalty mark,
// seen 100 times a second with the realistic perception profile's noise and
// misses (world::PerceptionSettings: range, bearing and self-pose noise,
// misses growing with distance), and a false ball elsewhere in 1 % of the
// periods (harsher than the profile, which adds one in 0.5 % of the periods
// the ball is missed: the fit's outlier step is exercised). Noise between two
// sightings a few periods apart reads as
// metres per second: the keeper must neither dive nor block before the ball
// moves (the referee gives a goal for a keeper down before the kick); a real
// shot after 20 s still gets a dive.
TEST(SoccerBehaviour, TheShootoutKeeperTakesNoiseForNoShotButDivesAtTheShot) {
  const auto cfg = soccerConfig();
  const auto f = field();
  const double x = -f.halfLength() + cfg.shootout_keeper_line;
  const double mark = -f.halfLength() + f.penalty_mark_distance.value();
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  agents::SoccerBehaviour keeper(cfg, f, 0, 1, 1, Role::PenaltyGoalkeeper, 1);
  const world::PerceptionSettings profile;  // the realistic profile's defaults
  double last_seen = -1.0;
  int acted_before = 0;
  std::optional<MotionRequest> at_shot;
  double ball_x_at_shot = 0.0;
  for (int i = 0; i < 2100 && !at_shot; ++i) {
    const double t = 0.01 * i;
    // Kicked at 20 s: 2 m/s towards 0.6 m to the keeper's left on its line.
    const double since = std::max(0.0, t - 20.0), dist = x - mark;
    const double bx = mark + dist * std::min(1.0, 2.0 * since / std::abs(dist));
    const double by = 0.6 * (bx - mark) / dist;
    if (since > 0.0 && bx <= x + 0.05) break;  // passed it
    agents::PerceptionIn p;
    p.sim_time = t;
    p.self_pose = {static_cast<float>(x + profile.pose_noise_xy * noise(rng)),
                   static_cast<float>(profile.pose_noise_xy * noise(rng)),
                   static_cast<float>(profile.pose_noise_yaw * noise(rng))};
    double rx = bx - x, ry = by;
    const double miss = profile.miss_base + profile.miss_per_metre * std::hypot(rx, ry);
    if (unit(rng) < 0.01) {  // a false ball somewhere in front of the keeper
      rx = 0.5 + 4.0 * unit(rng);
      ry = -3.0 + 6.0 * unit(rng);
    }
    const double d = std::hypot(rx, ry) * (1.0 + profile.distance_noise * noise(rng));
    const double bearing = std::atan2(ry, rx) + profile.bearing_noise * noise(rng);
    p.ball.in_view = unit(rng) > miss;
    if (p.ball.in_view) last_seen = t;
    p.ball.last_seen = last_seen;
    p.ball.x = static_cast<float>(d * std::cos(bearing));
    p.ball.y = static_cast<float>(d * std::sin(bearing));
    agents::SoccerBehaviour::Input in;
    in.time = t;
    in.perception = &p;
    const MotionRequest r = keeper.update(in);
    const bool acted = r.kind == MotionRequest::Kind::Block || r.kind == MotionRequest::Kind::Dive;
    if (acted && since == 0.0) ++acted_before;
    if (acted && since > 0.0) {
      at_shot = r;
      ball_x_at_shot = bx;
    }
  }
  EXPECT_EQ(acted_before, 0);
  ASSERT_TRUE(at_shot.has_value());
  EXPECT_EQ(at_shot->kind, MotionRequest::Kind::Dive);
  EXPECT_EQ(at_shot->side, agents::Leg::Left);
  EXPECT_GT(ball_x_at_shot - x, 0.3);  // in time for the dive to reach the ground
}

// The block and the dive on the real robot (Bullet, joint targets only): the
// block spreads the feet and lowers the torso without a fall, and the robot is
// back in its stance after it; the dive puts it on the ground on the side it
// was asked for, and it is counted as a dive, not as a fall.
TEST(MotionController, TheBlockStaysUpAndTheDiveLandsOnItsSide) {
  for (const auto kind : {MotionRequest::Kind::Block, MotionRequest::Kind::Dive}) {
    for (const auto side : {agents::Leg::Left, agents::Leg::Right}) {
      if (kind == MotionRequest::Kind::Block && side == agents::Leg::Right) continue;
      SCOPED_TRACE(kind == MotionRequest::Kind::Block ? "block"
                   : side == agents::Leg::Left        ? "dive left"
                                                      : "dive right");
      world::World w(test::scenario(1));
      const auto& model = *w.robot(0).model;
      agents::MotionController mc = controllerWithoutGetUp(model);
      std::vector<float> position(25), stiffness(25);
      const int lfoot = model.body->linkIndex("LFoot"), rfoot = model.body->linkIndex("RFoot");
      auto period = [&](const MotionRequest& r) { controlPeriod(w, mc, r, position, stiffness); };
      MotionRequest stand, act;
      for (int i = 0; i < 200; ++i) period(stand);  // into the stance
      ASSERT_EQ(mc.state(), agents::MotionState::Stance);
      const Vec3 torso0 = w.torsoPose(0).translation();
      const double feet0 =
          (w.linkPose(0, lfoot).translation() - w.linkPose(0, rfoot).translation()).y();
      act.kind = kind;
      act.side = side;
      period(act);
      double lowest = torso0.z(), widest = feet0;
      for (int i = 0; i < 80; ++i) {  // 0.8 s: the block held, the dive landed
        period(stand);
        lowest = std::min(lowest, w.torsoPose(0).translation().z());
        widest = std::max(
            widest, (w.linkPose(0, lfoot).translation() - w.linkPose(0, rfoot).translation()).y());
      }
      if (kind == MotionRequest::Kind::Block) {
        EXPECT_EQ(mc.state(), agents::MotionState::Blocking);
        EXPECT_GT(widest - feet0, 0.1);        // the feet spread sideways (0.146 measured)
        EXPECT_LT(lowest, torso0.z() - 0.03);  // and the torso goes down (0.044) ...
        // ... but not below World::isStanding's 0.22 m: to the referee (a
        // shoot-out keeper must stay on its feet) and the match summary's fall
        // count a block is not a fall.
        EXPECT_GT(lowest, 0.23);
        for (int i = 0; i < 300; ++i) period(stand);
        EXPECT_EQ(mc.state(), agents::MotionState::Stance);
        EXPECT_TRUE(w.isStanding(0));
        EXPECT_EQ(mc.counters().blocks, 1);
        EXPECT_EQ(mc.counters().falls, 0);
      } else {
        for (int i = 0; i < 200; ++i) period(stand);
        EXPECT_EQ(mc.state(), agents::MotionState::Lying);
        const Vec3 torso = w.torsoPose(0).translation();
        EXPECT_LT(torso.z(), 0.15);  // on the ground
        // Towards the side asked for (the robot faces +x: left is +y).
        EXPECT_GT((side == agents::Leg::Left ? 1 : -1) * (torso.y() - torso0.y()), 0.15);
        EXPECT_EQ(mc.counters().dives, 1);
        EXPECT_EQ(mc.counters().falls, 0);
      }
    }
  }
}

// The referee puts robots down (World::placeRobot: a penalty, a shoot-out kick).
// One lying soft (get-up off) is in the stance again at once; one put down
// while walking, facing the other way, neither reads the jump as a fall (the
// accelerometer's finite difference spanned it: it went soft and fell, as a
// shoot-out keeper did in the README match) nor, once the motion restarts as
// the agent restarts it at Set, is turned back by the walk's heading hold.
// Neither sinks below World::isStanding's height.
TEST(MotionController, ARobotPutDownByTheRefereeStaysUpAndKeepsItsNewHeading) {
  world::World w(test::scenario(1));
  agents::MotionController mc = controllerWithoutGetUp(*w.robot(0).model);
  std::vector<float> position(25), stiffness(25);
  MotionRequest stand;
  auto period = [&] { controlPeriod(w, mc, stand, position, stiffness); };
  for (int i = 0; i < 100; ++i) period();
  engine::Pose lying = engine::Pose::Identity();
  lying.linear() = Eigen::AngleAxisd(M_PI / 2, Vec3::UnitY()).toRotationMatrix();
  lying.translation() = Vec3(-2.0, 0.0, 0.16);
  w.placeRobot(0, lying, "stand");
  for (int i = 0; i < 300; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Lying);
  w.placeRobot(0, -2.0, 0.0, 0.0);
  EXPECT_GT(lowestTorsoOver(w, period, 300), 0.23);
  EXPECT_EQ(mc.state(), agents::MotionState::Stance);
  EXPECT_TRUE(w.isStanding(0));
  // Walking when it is put down facing the other way: it stops, stays up.
  MotionRequest walk;
  walk.kind = MotionRequest::Kind::Walk;
  walk.forward = 0.15;
  stand = walk;
  for (int i = 0; i < 200; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Walking);
  w.placeRobot(0, 2.0, 0.0, M_PI);
  mc.restart();  // as the agent does when the game enters Set (the referee places robots then)
  stand = MotionRequest{};
  EXPECT_GT(lowestTorsoOver(w, period, 300), 0.23);
  EXPECT_EQ(mc.state(), agents::MotionState::Stance);
  // Walking on from there: straight on in the new heading (the walk's heading
  // hold does not turn it back to the one it had before it was put down).
  stand = walk;
  for (int i = 0; i < 300; ++i) period();
  const double yaw = std::atan2(w.torsoPose(0).linear()(1, 0), w.torsoPose(0).linear()(0, 0));
  EXPECT_LT(std::abs(std::remainder(yaw - M_PI, 2 * M_PI)), 0.2);
  EXPECT_TRUE(w.isStanding(0));
}

TEST(KeyframeMotion, LoadsThePosesAndRejectsBadJoints) {
  const auto model = robots::loadRobotModel(test::naoH25());
  const auto m =
      agents::loadKeyframeMotion(test::sourceDir() / "configs/motions/get_up_front.yaml", model);
  EXPECT_GT(m.frames.size(), 3u);
  EXPECT_GT(m.duration(), 2.0);
  EXPECT_LT(m.duration(), 8.0);
  // The last frame is the stand pose.
  EXPECT_EQ(m.frames.back().position, model.pose("stand"));
  const test::TempDir dir("keyframes");
  std::ofstream(dir / "bad.yaml")
      << "motion: bad\nframes:\n  - {duration: 0.5, joints: {LKneePitch: 3.0}}\n";
  try {
    agents::loadKeyframeMotion(dir / "bad.yaml", model);
    FAIL();
  } catch (const engine::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("LKneePitch"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("limits"), std::string::npos) << e.what();
  }
  std::ofstream(dir / "bad.yaml")
      << "motion: bad\nframes:\n  - {duration: 0.5, joints: {RHipYawPitch: 0.1}}\n";
  EXPECT_THROW(agents::loadKeyframeMotion(dir / "bad.yaml", model),
               engine::ConfigError);  // a mimic joint
  // The player interpolates from the measured angles to the frames.
  agents::KeyframePlayer player;
  const std::vector<double> start(model.body->joints.size(), 0.0);
  player.start(m, start);
  std::vector<double> q(start.size());
  double k = 0;
  player.update(1e-3, q, k);
  EXPECT_NEAR(q[static_cast<size_t>(model.body->jointIndex("LKneePitch"))], 0.0, 1e-3);
  for (int i = 0; i < 10000 && player.active(); ++i) player.update(0.01, q, k);
  EXPECT_FALSE(player.active());
  EXPECT_EQ(q, model.pose("stand"));
}

// `interpolation: linear` moves at constant speed within a frame; the default
// (smoothstep) starts and ends each frame at rest. A bad value names the key.
TEST(KeyframeMotion, InterpolatesLinearlyOrSmoothly) {
  const auto model = robots::loadRobotModel(test::naoH25());
  const test::TempDir dir("keyframes_interp");
  const size_t knee = static_cast<size_t>(model.body->jointIndex("LKneePitch"));
  auto kneeAt = [&](const std::string& interp, double t) {
    std::ofstream(dir / "m.yaml") << "motion: m\n"
                                  << interp
                                  << "frames:\n  - {duration: 1.0, joints: {LKneePitch: 2.0}}\n";
    const auto m = agents::loadKeyframeMotion(dir / "m.yaml", model);
    agents::KeyframePlayer player;
    std::vector<double> q(model.body->joints.size(), 0.0);
    player.start(m, q);
    double k = 0;
    player.update(t, q, k);
    return q[knee];
  };
  EXPECT_NEAR(kneeAt("interpolation: linear\n", 0.25), 0.5, 1e-9);
  EXPECT_NEAR(kneeAt("", 0.25), 2.0 * 0.15625, 1e-9);  // smoothstep(0.25) = 0.15625
  EXPECT_NEAR(kneeAt("interpolation: smooth\n", 0.25), 2.0 * 0.15625, 1e-9);
  try {
    kneeAt("interpolation: cubic\n", 0.5);
    FAIL();
  } catch (const engine::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("interpolation"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("smooth or linear"), std::string::npos) << e.what();
  }
}

TEST(MotionController, TheFallDetectorGoesSoftWhileFallingAndStaysDownWithoutGetUp) {
  const auto model = robots::loadRobotModel(test::naoH25());
  agents::MotionController mc = controllerWithoutGetUp(model);
  std::vector<float> joints(25, 0.0f), position(25), stiffness(25);
  const auto& stand = model.pose("stand");
  for (size_t a = 0; a < model.actuators.size(); ++a)
    if (model.actuators[a].kind == robots::Actuator::Kind::Joint)
      joints[a] = static_cast<float>(stand[static_cast<size_t>(model.actuators[a].index)]);
  agents::MotionSensors s;
  s.position = joints;
  MotionRequest stand_still;
  for (int i = 0; i < 100; ++i) mc.update(0.01, s, stand_still, position, stiffness);
  EXPECT_EQ(mc.state(), agents::MotionState::Stance);
  EXPECT_FLOAT_EQ(stiffness[static_cast<size_t>(model.actuatorIndex("LKneePitch"))], 1.0f);
  // Tipping forward: up (the accelerometer) leans towards -x in the torso frame.
  for (int i = 0; i < 30; ++i) {
    const double a = std::min(1.5, 0.05 * i);
    s.accel = Vec3(-9.81 * std::sin(a), 0, 9.81 * std::cos(a));
    s.pitch = a;  // the IMU's angle
    s.gyro = Vec3(0, 2.0, 0);
    mc.update(0.01, s, stand_still, position, stiffness);
  }
  EXPECT_EQ(mc.counters().falls, 1);
  EXPECT_LT(stiffness[static_cast<size_t>(model.actuatorIndex("LKneePitch"))], 0.3f);
  // Lying still: stays down (get-up off), soft.
  s.gyro = Vec3::Zero();
  for (int i = 0; i < 100; ++i) mc.update(0.01, s, stand_still, position, stiffness);
  EXPECT_EQ(mc.state(), agents::MotionState::Lying);
  EXPECT_EQ(mc.counters().get_ups, 0);
}

// A roll: a get-up whose motion `ends: front` (the Nao's roll that starts its get-up from the
// back) or `ends: back` (the Booster K1's roll that starts its get-up from the front) leaves
// the robot lying on that side on purpose: no failed get-up, and the get-up from that side
// follows once it lies still. One that leaves it where it started failed.
namespace {
void expectTheRollIsFollowedByTheOtherGetUp(bool from_back) {
  const auto model = robots::loadRobotModel(test::naoH25());
  const test::TempDir dir(from_back ? "roll_front_motions" : "roll_back_motions");
  for (const auto& f : std::filesystem::directory_iterator(test::sourceDir() / "configs/motions"))
    if (f.is_regular_file()) std::filesystem::copy_file(f.path(), dir / f.path().filename());
  const std::string roll = from_back ? "get_up_back" : "get_up_front";
  const std::string other = from_back ? "get_up_front" : "get_up_back";
  std::filesystem::remove(dir / (roll + ".yaml"));
  std::ofstream(dir / (roll + ".yaml"))
      << "motion: " << roll << "\nends: " << (from_back ? "front" : "back")
      << "\nframes:\n  - {duration: 0.5, joints: {LKneePitch: 1.0}}\n";
  EXPECT_EQ(agents::loadKeyframeMotion(dir / (roll + ".yaml"), model).ends,
            from_back ? agents::KeyframeMotion::Ends::Front : agents::KeyframeMotion::Ends::Back);
  // Up is +x in the torso frame lying on the back, -x on the front.
  const double start_up = from_back ? 9.81 : -9.81;
  for (const bool rolled : {true, false}) {
    agents::FallDetectorParameters fall;
    fall.get_up = true;
    agents::MotionController mc = agents::loadMotionController(model, dir.path(), fall);
    std::vector<float> joints(25, 0.0f), position(25), stiffness(25);
    agents::MotionSensors s;
    s.position = joints;
    MotionRequest stand;
    auto run = [&](double seconds) {
      for (int i = 0; i < static_cast<int>(seconds / 0.01); ++i)
        mc.update(0.01, s, stand, position, stiffness);
    };
    run(0.5);
    s.accel = Vec3(start_up, 0, 0);
    s.pitch = from_back ? -M_PI / 2 : M_PI / 2;
    for (int i = 0; i < 300 && mc.state() != agents::MotionState::GettingUp; ++i) run(0.01);
    ASSERT_EQ(mc.state(), agents::MotionState::GettingUp);  // the roll
    if (rolled) {                                           // now on the other side
      s.accel = Vec3(-start_up, 0, 0);
      s.pitch = -s.pitch;
    }
    run(0.55);
    EXPECT_EQ(mc.state(), agents::MotionState::Lying) << rolled;
    EXPECT_EQ(mc.counters().failed_get_ups, rolled ? 0 : 1);
    run(0.5);
    ASSERT_EQ(mc.state(), agents::MotionState::GettingUp) << rolled;
    ASSERT_NE(mc.keyframeMotion(), nullptr);
    EXPECT_EQ(mc.keyframeMotion()->name, rolled ? other : roll);
  }
}
}  // namespace

TEST(MotionController, ARollOntoTheFrontIsFollowedByTheGetUpFromTheFront) {
  expectTheRollIsFollowedByTheOtherGetUp(true);
}

TEST(MotionController, ARollOntoTheBackIsFollowedByTheGetUpFromTheBack) {
  expectTheRollIsFollowedByTheOtherGetUp(false);
}

// A motion file's `ends` is standing, front or back; anything else names the key.
TEST(MotionController, AnUnknownEndsValueIsRefusedNamingTheKey) {
  const auto model = robots::loadRobotModel(test::naoH25());
  const test::TempDir dir("ends_motion");
  std::ofstream(dir / "m.yaml") << "motion: m\nends: sideways\nframes:\n  - "
                                   "{duration: 0.5, joints: {LKneePitch: 1.0}}\n";
  try {
    agents::loadKeyframeMotion(dir / "m.yaml", model);
    FAIL() << "accepted ends: sideways";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("ends"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("standing, front or back"), std::string::npos) << e.what();
  }
}

// A robot picked up in the middle of its get-up (the referee removing an
// inactive player) or of a dive (the shoot-out's next kick) and put on its
// feet stops the motion and eases into the stance, instead of playing the rest
// of it from standing and falling at its waiting spot (as in a 5 v 5 match).
TEST(MotionController, ARobotPutOnItsFeetDuringAGetUpOrADiveStaysUp) {
  GettingUp rig;
  world::World& w = rig.w;
  agents::MotionController& mc = rig.mc;
  MotionRequest& request = rig.request;
  auto period = [&] { rig.period(); };
  const engine::Pose lying = onItsFront();
  ASSERT_EQ(mc.state(), agents::MotionState::GettingUp);
  for (int t : {100, 250}) {  // 1 s and 2.5 s into the get-up
    for (int i = 0; i < t; ++i) period();
    ASSERT_EQ(mc.state(), agents::MotionState::GettingUp) << t;
    const int falls = mc.counters().falls;
    w.placeRobot(0, -2.0, 0.0, 0.0);
    for (int i = 0; i < 300; ++i) period();
    EXPECT_EQ(mc.state(), agents::MotionState::Stance) << t;
    EXPECT_TRUE(w.isStanding(0)) << t;
    EXPECT_EQ(mc.counters().failed_get_ups, 0) << t;
    EXPECT_EQ(mc.counters().falls, falls) << t;  // put on its feet is not a fall
    w.placeRobot(0, lying, "stand");             // down again for the next one
    for (int i = 0; i < 300 && mc.state() != agents::MotionState::GettingUp; ++i) period();
  }
  // A dive, put on its feet while it lies (the dive's last frames).
  for (int i = 0; i < 800 && mc.state() != agents::MotionState::Stance; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Stance);
  request.kind = MotionRequest::Kind::Dive;
  request.side = agents::Leg::Left;
  period();
  request = MotionRequest{};
  ASSERT_EQ(mc.state(), agents::MotionState::Diving);
  for (int i = 0; i < 60; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Diving);
  w.placeRobot(0, -2.0, 0.0, 0.0);
  for (int i = 0; i < 300; ++i) period();
  EXPECT_EQ(mc.state(), agents::MotionState::Stance);
  EXPECT_TRUE(w.isStanding(0));
  // Dived and lying when the shoot-out's next kick is set up: the agent
  // restarts its motion at Set (stiff, still on the ground: a fall, soft
  // again), then the referee puts it on its feet. Stiff at once, it stays up.
  request.kind = MotionRequest::Kind::Dive;
  period();
  request = MotionRequest{};
  for (int i = 0; i < 300 && mc.state() != agents::MotionState::Lying; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Lying);
  mc.restart();
  for (int i = 0; i < 5; ++i) period();
  ASSERT_TRUE(mc.state() == agents::MotionState::Falling ||
              mc.state() == agents::MotionState::Lying);
  w.placeRobot(0, -2.0, 0.0, 0.0);
  EXPECT_GT(lowestTorsoOver(w, period, 300), 0.23);
  EXPECT_EQ(mc.state(), agents::MotionState::Stance);
}

// Penalised in the middle of a get-up: the referee sets the robot down upright on the touchline
// and the agent restarts its motion in the same period (the GameState's penalty). The fall
// detector restarts from the IMU too: no fall is read from the get-up's filtered tilt (before:
// it read one, went soft for a moment and sagged, and a K1 then tipped over backwards).
TEST(MotionController, ARestartAsTheRefereeSetsTheRobotDownIsNotAFall) {
  GettingUp rig;
  world::World& w = rig.w;
  agents::MotionController& mc = rig.mc;
  auto period = [&] { rig.period(); };
  ASSERT_EQ(mc.state(), agents::MotionState::GettingUp);
  for (int i = 0; i < 50; ++i) period();
  const int falls = mc.counters().falls;
  w.placeRobot(0, -2.0, 3.5, -M_PI / 2);
  mc.restart();
  std::set<agents::MotionState> states;
  for (int i = 0; i < 300; ++i) {
    period();
    states.insert(mc.state());
  }
  EXPECT_EQ(mc.counters().falls, falls);
  EXPECT_FALSE(states.count(agents::MotionState::Falling));
  EXPECT_EQ(mc.state(), agents::MotionState::Stance);
  EXPECT_TRUE(w.isStanding(0));
}

TEST(MatchLog, RoundTripsFramesAndSurvivesATruncatedTail) {
  world::World w(test::scenario(2));
  const test::TempDir dir("match_log");
  const auto file = dir / "test.log";
  world::MatchLogHeader h;
  h.values["scenario"] = "x.yaml";
  h.values["seed"] = "9";
  for (world::RobotId r = 0; r < w.robotCount(); ++r)
    h.robots.push_back({w.robot(r).team, w.robot(r).number,
                        static_cast<int>(w.robot(r).model->body->joints.size())});
  std::vector<world::LogFrame> written;
  {
    world::MatchLogWriter log(file, h);
    std::vector<std::array<double, 25>> pos(w.robotCount()), stiff(w.robotCount());
    for (int i = 0; i < 250; ++i) {
      for (auto& p : pos) p[3] = world::quantizeCommand(0.001 * i);
      for (auto& k : stiff) k[3] = world::quantizeStiffness(0.5);
      w.stepControlPeriod();
      world::LogFrame f = world::captureFrame(w, static_cast<uint64_t>(i + 1), pos, stiff,
                                              std::vector<bool>(w.robotCount(), i % 2 == 0));
      if (i == 7) f.events.push_back({0.08, "goal", 1, 3, "0:1"});
      if (i % 3 == 0) f.robots[1].leds = std::array<uint8_t, 9>{0, 0, 255, 10, 20, 30, 40, 50, 60};
      f.game = {1, 2, 3};
      log.write(f);
      written.push_back(f);
    }
  }
  world::MatchLogReader in(file);
  EXPECT_EQ(in.header().values.at("seed"), "9");
  ASSERT_EQ(in.header().robots.size(), w.robotCount());
  world::LogFrame f;
  size_t n = 0;
  while (in.next(f)) {
    const auto& o = written[n];
    EXPECT_EQ(f.tick, o.tick);
    EXPECT_EQ(f.state_hash, o.state_hash);
    EXPECT_EQ(f.game, o.game);
    EXPECT_NEAR((f.robots[0].torso.translation() - o.robots[0].torso.translation()).norm(), 0,
                1e-6);
    EXPECT_NEAR(f.robots[1].joints[5], o.robots[1].joints[5], 1e-4);
    EXPECT_EQ(f.robots[0].command_position[3], o.robots[0].command_position[3]);  // exact
    EXPECT_EQ(f.robots[0].command_stiffness[3], o.robots[0].command_stiffness[3]);
    EXPECT_EQ(f.robots[0].commanded, o.robots[0].commanded);
    EXPECT_EQ(f.robots[0].leds, o.robots[0].leds);
    EXPECT_EQ(f.robots[1].leds, o.robots[1].leds);
    EXPECT_EQ(f.events.size(), o.events.size());
    ++n;
  }
  EXPECT_EQ(n, written.size());
  EXPECT_FALSE(in.truncatedAt().has_value());
  // Cut the file in the last block: the complete blocks still read, and the
  // reader says where the log was cut.
  const auto full = std::filesystem::file_size(file);
  std::filesystem::resize_file(file, full - 100);
  world::MatchLogReader cut(file);
  n = 0;
  while (cut.next(f)) ++n;
  EXPECT_EQ(n, 200u);
  ASSERT_TRUE(cut.truncatedAt().has_value());
  EXPECT_LT(*cut.truncatedAt(), full - 100);
  // Length fields that claim gigabytes: an error naming the file, no allocation of them.
  {
    std::fstream patch(file, std::ios::in | std::ios::out | std::ios::binary);
    patch.seekp(12);  // the header's length
    const uint32_t huge = 0xfffffff0u;
    patch.write(reinterpret_cast<const char*>(&huge), 4);
  }
  try {
    world::MatchLogReader bad(file);
    FAIL() << "a header length of 4 GiB was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("claims"), std::string::npos) << e.what();
  }
  // Not a log: a clear error.
  std::ofstream(file) << "hello";
  EXPECT_THROW(world::MatchLogReader{file}, std::runtime_error);
  std::filesystem::remove(file);
}

// Sitting down when the game is over: a crouch on the feet that the referee
// and the match summary still count as standing (World::isStanding: torso
// above 0.22 m, within 45 degrees of upright), resting on soft joints, and
// back up into the stance on the next other request.
TEST(MotionController, SitsDownOnItsFeetRestsSoftAndStandsUpAgain) {
  world::World w(test::scenario(1));
  agents::MotionController mc =
      agents::loadMotionController(*w.robot(0).model, test::sourceDir() / "configs/motions");
  std::vector<float> position(25), stiffness(25);
  MotionRequest request;
  request.kind = MotionRequest::Kind::Walk;
  request.forward = 0.2;
  auto period = [&] { controlPeriod(w, mc, request, position, stiffness); };
  for (int i = 0; i < 200; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Walking);
  const double standing = w.torsoPose(0).translation().z();
  request = MotionRequest{};
  request.kind = MotionRequest::Kind::Sit;
  // The walk stops first, then it sits down.
  for (int i = 0; i < 300 && mc.state() != agents::MotionState::SittingDown; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::SittingDown);
  EXPECT_FALSE(mc.walk().walking());
  double lowest = 1.0;
  for (int i = 0; i < 500; ++i) {  // 5 s: down (1.5 s), then resting
    period();
    lowest = std::min(lowest, w.torsoPose(0).translation().z());
    ASSERT_TRUE(w.isStanding(0)) << i;
  }
  EXPECT_EQ(mc.state(), agents::MotionState::Sitting);
  const double sitting = w.torsoPose(0).translation().z();
  EXPECT_LT(sitting, standing - 0.05);
  EXPECT_GT(lowest, 0.225);
  for (size_t a = 0; a < 25; ++a) EXPECT_LE(stiffness[a], 0.31f) << a;
  EXPECT_EQ(mc.counters().sits, 1);
  // Anything else stands it up, then the stance and the request follow.
  const auto standsUp = [&] {
    request = MotionRequest{};
    period();
    EXPECT_EQ(mc.state(), agents::MotionState::StandingUp);
    for (int i = 0; i < 300; ++i) {
      period();
      ASSERT_TRUE(w.isStanding(0)) << i;
    }
    EXPECT_EQ(mc.state(), agents::MotionState::Stance);
  };
  standsUp();
  EXPECT_NEAR(w.torsoPose(0).translation().z(), standing, 0.02);
  // Asked to sit for a moment only: up again from half-way down.
  request.kind = MotionRequest::Kind::Sit;
  for (int i = 0; i < 50; ++i) period();
  EXPECT_EQ(mc.state(), agents::MotionState::SittingDown);
  standsUp();
  EXPECT_EQ(mc.counters().sits, 2);
  // Restarted while sitting (the behaviour does at the next half's Initial):
  // up by the stand-up motion too, not eased from the crouch.
  request.kind = MotionRequest::Kind::Sit;
  for (int i = 0; i < 300 && mc.state() != agents::MotionState::Sitting; ++i) period();
  ASSERT_EQ(mc.state(), agents::MotionState::Sitting);
  mc.restart();
  period();
  EXPECT_EQ(mc.state(), agents::MotionState::StandingUp);
  standsUp();
  EXPECT_EQ(mc.counters().sits, 3);
  EXPECT_EQ(mc.counters().falls, 0);
}
