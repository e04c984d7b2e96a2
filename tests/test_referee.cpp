// The automatic referee on the real world (real Bullet): scripted ball
// positions and robot placements, checked against the rules.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "referee_support.hpp"
#include "simsoccer/referee/referee.hpp"

using namespace simsoccer;
using namespace simsoccer::referee;
using engine::Vec3;

namespace {

// 2 v 2 in their own halves: team 0 defends -x.
world::Scenario twoVsTwo() {
  world::Scenario s = test::scenario(0);
  s.ball_position = {0.0, 0.0, -1.0};
  const double xs[2][2] = {{-3.0, -1.5}, {3.0, 1.5}};
  for (int team = 0; team < 2; ++team)
    for (int n = 0; n < 2; ++n) {
      world::RobotPlacement p;
      p.team = team;
      p.number = n + 1;
      p.x = xs[team][n];
      p.y = n == 0 ? 0.0 : 1.0;
      p.yaw = team == 0 ? 0.0 : M_PI;
      s.robots.push_back(p);
    }
  return s;
}

RuleBook hslRules() {
  return loadRuleBook(test::sourceDir() / "configs" / "rules" / "hsl_small_foundation.yaml");
}

void run(world::World& w, Referee& ref, double seconds) {
  const int periods = static_cast<int>(std::lround(seconds / w.scenario().physics.control_period));
  for (int i = 0; i < periods; ++i) {
    w.stepControlPeriod();
    ref.update();
  }
}

void putBall(world::World& w, double x, double y, double z = 0.05) {
  engine::RigidBodyState b;
  b.pose = engine::Pose::Identity();
  b.pose.translation() = Vec3(x, y, z);
  w.setBallState(b);
}

// Lets a robot touch the ball: the ball is put against its left foot's toe.
void touchBall(world::World& w, Referee& ref, world::RobotId r) {
  const int foot = w.robot(r).model->body->linkIndex("LFoot");
  const engine::Pose p = w.linkPose(r, foot);
  const Vec3 toe = p * Vec3(0.12, 0.0075, -0.02);
  putBall(w, toe.x(), toe.y(), 0.05);
  run(w, ref, 0.05);
  ASSERT_TRUE(w.lastBallTouch().has_value());
  ASSERT_EQ(w.lastBallTouch()->robot, r);
}

int count(const Game& g, const std::string& type) {
  int n = 0;
  for (const auto& e : g.events()) n += referee::eventName(e.type) == std::string(type);
  return n;
}

void kickOff(world::World& w, Referee& ref) {
  // Ready ends early (robots stand still where they are, legally), Set, whistle.
  for (int i = 0; i < 1000 && ref.game().state() != gc::State::Playing; ++i) run(w, ref, 0.01);
  ASSERT_EQ(ref.game().state(), gc::State::Playing);
}

// The scenario (2 v 2 unless told) right after team 0's kick-off under the rule book.
struct KickedOff {
  world::World w;
  Referee ref;
  Game& g = ref.game();
  explicit KickedOff(const RuleBook& rules = test::splRules(),
                     const world::Scenario& scenario = twoVsTwo())
      : w(scenario), ref(w, rules, test::twoTeams(), 0) {
    g.ready();
    kickOff(w, ref);
  }
};

// From the first kick-off to open play (the ball free).
void openPlay(world::World& w, Referee& ref) {
  ref.game().ready();
  kickOff(w, ref);
  ref.game().ballFree();
}

// From open play, team 1 (robot 2) plays the ball last over the left touchline: team 0's kick-in.
void kickInForTeam0(world::World& w, Referee& ref) {
  openPlay(w, ref);
  touchBall(w, ref, 2);
  putBall(w, 1.2, w.field().halfWidth() + 0.2);
  run(w, ref, 0.02);
  ASSERT_EQ(ref.game().currentSetPlay(), gc::SetPlay::KickIn);
  ASSERT_EQ(ref.game().kickingTeam(), 0);
}

// Team 0 player 2 (robot 1) and team 1 player 2 (robot 3) face each other
// 0.35 m apart, the ball 0.3 m to their side.
void faceOff(world::World& w) {
  w.placeRobot(1, 0.45, -2.0, 0.0);
  w.placeRobot(3, 0.8, -2.0, M_PI);
  putBall(w, 0.7, -1.7);
}

// In open play, team 0 player 2 (robot 1) and team 1 player 2 (robot 3) face each other, the
// ball beside them, for 0.5 s.
void faceOffInOpenPlay(world::World& w, Referee& ref) {
  openPlay(w, ref);
  faceOff(w);
  run(w, ref, 0.5);
}

}  // namespace

TEST(Referee, FirstHalfWithScriptedBall) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  g.ready();
  const double t0 = g.time();
  run(w, ref, 1.6);
  EXPECT_EQ(g.state(), gc::State::Set) << "Ready ends once all stand still in legal places";
  EXPECT_LT(g.time() - t0, 3.0);
  run(w, ref, 5.1);
  ASSERT_EQ(g.state(), gc::State::Playing);
  EXPECT_EQ(g.kickingTeam(), 0);

  // A goal in the +x goal: team 0 (attacking +x in the first half) scores,
  // after two of its robots played the ball (indirect kick).
  touchBall(w, ref, 0);
  touchBall(w, ref, 1);
  putBall(w, 4.7, 0.2);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(g.state(), gc::State::Ready);
  EXPECT_EQ(g.kickingTeam(), 1);  // the conceding team kicks off
  EXPECT_LT(w.ballState().pose.translation().head<2>().norm(), 0.01);  // back on the centre mark
  kickOff(w, ref);
  g.ballFree();

  // Kick-in: team 1 (robot 2) touches the ball last, it leaves over the touchline.
  touchBall(w, ref, 2);
  putBall(w, 1.2, 3.2);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::KickIn);
  EXPECT_EQ(g.kickingTeam(), 0);
  EXPECT_NEAR(w.ballState().pose.translation().y(), 3.0, 1e-3);  // on the touchline
  EXPECT_NEAR(w.ballState().pose.translation().x(), 1.2, 1e-3);  // where it went out
  run(w, ref, 30.1);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);  // its 30 s are over

  // Corner kick: the -x goal's defender (team 0) touched it last, over its goal line.
  touchBall(w, ref, 0);
  putBall(w, -4.7, -2.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::CornerKick);
  EXPECT_EQ(g.kickingTeam(), 1);
  EXPECT_NEAR(w.ballState().pose.translation().x(), -4.5, 1e-3);
  EXPECT_NEAR(w.ballState().pose.translation().y(), -3.0, 1e-3);
  g.ballFree();

  // Goal kick: the +x goal's attacker (team 0) touched it last, over that goal line.
  touchBall(w, ref, 1);
  putBall(w, 4.7, 2.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);
  EXPECT_EQ(g.kickingTeam(), 1);
  EXPECT_NEAR(w.ballState().pose.translation().x(), 3.9, 1e-3);  // goal-area corner
  EXPECT_NEAR(w.ballState().pose.translation().y(), 1.1, 1e-3);
  // The kicking team moves the ball: the set play is over.
  touchBall(w, ref, 2);
  putBall(w, 3.5, 1.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);

  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(g.score(1), 0);
  EXPECT_EQ(count(g, "goal"), 1);
  EXPECT_GE(count(g, "set_play"), 6);  // 3 awarded, 3 over
  EXPECT_EQ(count(g, "set_play"), 8);  // and the two kick-offs over
}

TEST(Referee, LeavingTheFieldRemovesAndReturnsTheRobotWithTheIncrement) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  g.ready();
  kickOff(w, ref);
  w.placeRobot(1, -2.0, -3.6, 0.0);  // walks off: next to the carpet's edge ...
  w.placeRobot(1, -2.0, -3.9, 0.0);  // ... and beyond it
  run(w, ref, 0.02);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::LeavingTheField);
  EXPECT_NEAR(g.penaltyTime(0, 2), 45, 0.05);
  // Removed: 0.5 m outside a touchline, level with its own penalty mark (x = -3.2).
  const Vec3 out = w.torsoPose(1).translation();
  EXPECT_NEAR(std::abs(out.y()), 3.5, 0.01);
  EXPECT_NEAR(out.x(), -3.2, 0.01);
  EXPECT_TRUE(w.isStanding(1));
  // A second incremental penalty of the team: 55 s.
  w.placeRobot(0, -5.4, 0.0, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.penalty(0, 1), gc::Penalty::LeavingTheField);
  EXPECT_NEAR(g.penaltyTime(0, 1), 55, 0.05);
  // After its 45 s it comes back onto the touchline (the ball keeps moving
  // meanwhile, so no game stuck interrupts Playing).
  g.ballFree();
  for (int i = 0; i < 9; ++i) {
    putBall(w, 0.5 * (i % 3), -1.0 + 0.8 * (i % 2));
    run(w, ref, 5.0);
  }
  run(w, ref, 0.1);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::None);
  EXPECT_NEAR(std::abs(w.torsoPose(1).translation().y()), 3.0, 0.05);
  EXPECT_EQ(g.penalty(0, 1), gc::Penalty::LeavingTheField);  // still 10 s to go
  putBall(w, 1.0, 1.0);
  run(w, ref, 10.1);
  EXPECT_EQ(g.penalty(0, 1), gc::Penalty::None);
}

// Motion in Set (called by a GameController the simulation follows, or an operator) is served
// in place under the SPL's rules: the robot stays where it is, unlike every other penalty.
TEST(Referee, MotionInSetIsServedInPlace) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  g.ready();
  run(w, ref, 0.1);
  if (g.state() == gc::State::Ready) g.set();  // (the referee may call Set itself)
  ASSERT_EQ(g.state(), gc::State::Set);
  const Vec3 before = w.torsoPose(1).translation();
  g.penalise(0, 2, gc::Penalty::IllegalMotionInSet);
  run(w, ref, 0.5);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::IllegalMotionInSet);
  EXPECT_LT((w.torsoPose(1).translation() - before).head<2>().norm(), 0.05);
  // Another penalty takes it off the field.
  g.unpenalise(0, 2);
  g.penalise(0, 2, gc::Penalty::RequestForPickup);
  run(w, ref, 0.1);
  EXPECT_GT((w.torsoPose(1).translation() - before).head<2>().norm(), 0.5);
  // Under the HSL's rules Motion in Set is a standard removal penalty.
  world::World hsl_world(twoVsTwo());
  Referee hsl(hsl_world,
              loadRuleBook(test::sourceDir() / "configs" / "rules" / "hsl_small_foundation.yaml"),
              test::twoTeams(), 0);
  EXPECT_FALSE(hsl.game().rules().motion_in_set_in_place);
  hsl.game().ready();
  run(hsl_world, hsl, 0.1);
  if (hsl.game().state() == gc::State::Ready) hsl.game().set();
  const Vec3 at = hsl_world.torsoPose(1).translation();
  hsl.game().penalise(0, 2, gc::Penalty::IllegalMotionInSet);
  run(hsl_world, hsl, 0.1);
  EXPECT_GT((hsl_world.torsoPose(1).translation() - at).head<2>().norm(), 0.5);
}

TEST(Referee, IllegalPositionInSetOrAutoPlacement) {
  for (const bool auto_place : {false, true}) {
    world::World w(twoVsTwo());
    RefereeConfig cfg;
    cfg.auto_placement = auto_place;
    Referee ref(w, test::splRules(), test::twoTeams(), 0, cfg);
    Game& g = ref.game();
    g.ready();
    w.placeRobot(3, -1.0, 1.0, M_PI);  // team 1 player 2 in the opponents' half
    run(w, ref, 45.1);                 // Ready runs out (not everyone is legal)
    ASSERT_EQ(g.state(), gc::State::Set);
    if (auto_place) {
      EXPECT_EQ(g.penalty(1, 2), gc::Penalty::None);
      // Moved to the nearest legal spot: just inside its own half, outside the circle.
      const Vec3 p = w.torsoPose(3).translation();
      EXPECT_GT(p.x(), 0.2);
      EXPECT_LT(p.x(), 0.6);
      EXPECT_GT(std::hypot(p.x(), p.y()), w.field().centre_circle_radius);
    } else {
      EXPECT_EQ(g.penalty(1, 2), gc::Penalty::IllegalPositionInSet);
      EXPECT_NEAR(g.penaltyTime(1, 2), 15, 1e-9);
    }
  }
}

TEST(Referee, TooManyDefendersInTheGoalArea) {
  world::Scenario s = twoVsTwo();
  // Team 0 gets two more robots: four in all.
  for (int n = 3; n <= 4; ++n) {
    world::RobotPlacement p;
    p.team = 0;
    p.number = n;
    p.x = -2.0;
    p.y = -2.0 + 0.6 * n;
    s.robots.push_back(p);
  }
  world::World w(s);
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  g.ready();
  kickOff(w, ref);
  // All four of team 0 into their own goal area (x in [-4.5, -3.9], |y| <= 1.1).
  const world::RobotId team0[4] = {0, 1, 4, 5};
  const double ys[4] = {-0.8, -0.3, 0.25, 0.8};
  const double xs[4] = {-4.3, -4.1, -4.0, -4.2};
  for (int i = 0; i < 4; ++i) w.placeRobot(team0[i], xs[i], ys[i], 0.0);
  run(w, ref, 0.02);
  int penalised = 0;
  for (int n = 1; n <= 4; ++n) penalised += g.penalty(0, n) == gc::Penalty::IllegalPosition;
  EXPECT_EQ(penalised, 1);
  // All entered together: the one closest to the area's border (player 3,
  // 0.1 m from the front line) goes.
  EXPECT_EQ(g.penalty(0, 3), gc::Penalty::IllegalPosition);

  // In Playing the robot that enters as the extra one is penalised, even
  // when it goes deeper than the others.
  g.unpenalise(0, 3);
  run(w, ref, 0.02);                 // re-enters at the touchline
  w.placeRobot(5, -3.0, 2.0, 0.0);   // player 4 leaves
  w.placeRobot(4, -4.0, 0.25, 0.0);  // player 3 back in the area: three now
  run(w, ref, 0.02);
  ASSERT_EQ(g.penalty(0, 3), gc::Penalty::None);
  w.placeRobot(5, -4.45, 0.0, 0.0);  // player 4 walks in as the fourth
  run(w, ref, 0.02);
  penalised = 0;
  for (int n = 1; n <= 4; ++n) penalised += g.penalty(0, n) == gc::Penalty::IllegalPosition;
  EXPECT_EQ(penalised, 1);
  EXPECT_EQ(g.penalty(0, 4), gc::Penalty::IllegalPosition);
}

TEST(Referee, FallenRobotIsPenalisedAsInactive) {
  // Down for the rule book's time: 10 s in the SPL's, 20 s in the HSL's.
  for (const bool hsl : {false, true}) {
    const double limit = hsl ? 20.0 : 10.0;
    KickedOff game(hsl ? hslRules() : test::splRules());
    auto& [w, ref, g] = game;
    const auto& joints = w.robot(3).model->body->joints;
    for (int j = 0; j < static_cast<int>(joints.size()); ++j)
      if (joints[static_cast<size_t>(j)].mimic_of < 0) w.setJointTarget(3, j, 0.0, 0.0);  // limp
    run(w, ref, limit - 1.0);
    EXPECT_EQ(g.penalty(1, 2), gc::Penalty::None) << hsl;
    EXPECT_EQ(count(g, "inactive"), 0);
    run(w, ref, 3.0);
    EXPECT_EQ(g.penalty(1, 2), gc::Penalty::InactivePlayer) << hsl;
    // The call is in the game's record, as every other penalty's reason.
    ASSERT_EQ(count(g, "inactive"), 1);
    for (const auto& e : g.events())
      if (e.type == EventType::Inactive) {
        EXPECT_EQ(e.team, 1);
        EXPECT_EQ(e.player, 2);
        EXPECT_NE(e.detail.find(hsl ? "down for 20 s" : "down for 10 s"), std::string::npos)
            << e.detail;
      }
  }
}

namespace {

// Tips robot r over: its ankles pitched hard (a limp robot set down upright may settle in a
// crouch that counts as standing).
void tipOver(world::World& w, world::RobotId r) {
  const auto& joints = w.robot(r).model->body->joints;
  for (int j = 0; j < static_cast<int>(joints.size()); ++j)
    if (joints[static_cast<size_t>(j)].mimic_of < 0 &&
        joints[static_cast<size_t>(j)].name.find("AnklePitch") != std::string::npos)
      w.setJointTarget(r, j, 0.9, 1.0);
}

}  // namespace

TEST(Referee, FailedGetUpsArePenalisedAsInactive) {
  // Team 1 player 2 (robot 3) tips over; each "get-up" sets it upright, where it tips over
  // again within 2 s. The rules: 2 failed get-ups are Inactive Player, 3 if another robot
  // disturbed it (here team 1's keeper, robot 2, beside it); the HSL's: 3, and 4.
  for (const bool hsl : {false, true})
    for (const bool disturbed : {false, true}) {
      KickedOff game(hsl ? hslRules() : test::splRules());
      auto& [w, ref, g] = game;
      const Vec3 at = w.torsoPose(3).translation();
      if (disturbed) w.placeRobot(2, at.x(), at.y() + 0.5, M_PI);
      tipOver(w, 3);
      run(w, ref, 2.0);  // down from standing: a fall, not a failed get-up
      ASSERT_FALSE(w.isStanding(3));
      int failed = 0;
      while (g.penalty(1, 2) == gc::Penalty::None && failed < 5) {
        w.placeRobot(3, at.x(), at.y(), M_PI);  // up ...
        run(w, ref, 0.2);
        ASSERT_TRUE(w.isStanding(3));
        tipOver(w, 3);
        run(w, ref, 2.0);  // ... and down again within the hold time (3 s)
        ++failed;
        // (Penalised, it stands off the field.)
        if (g.penalty(1, 2) == gc::Penalty::None) {
          ASSERT_FALSE(w.isStanding(3));
        }
      }
      EXPECT_EQ(g.penalty(1, 2), gc::Penalty::InactivePlayer) << "disturbed " << disturbed;
      EXPECT_EQ(failed, (disturbed ? 3 : 2) + (hsl ? 1 : 0)) << "hsl " << hsl;
      EXPECT_EQ(count(g, "inactive"), 1);
      EXPECT_EQ(g.penalty(1, 1), gc::Penalty::None);  // the robot beside it
    }
  // A robot that stands for the hold time between two falls did get up: no call.
  KickedOff game;
  auto& [w, ref, g] = game;
  const Vec3 at = w.torsoPose(3).translation();
  for (int fall = 0; fall < 3; ++fall) {
    tipOver(w, 3);
    run(w, ref, 2.0);
    ASSERT_FALSE(w.isStanding(3));
    w.placeRobot(3, at.x(), at.y(), M_PI);
    run(w, ref, 3.5);
  }
  EXPECT_EQ(g.penalty(1, 2), gc::Penalty::None);
}

TEST(Referee, StandingIdleNextToTheBallIsInactive) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  openPlay(w, ref);
  putBall(w, 2.75, 0.05);  // in front of team 1 player 1, who does not move
  run(w, ref, 9.5);
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::None);
  run(w, ref, 1.0);
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::InactivePlayer);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::None);  // far from the ball
}

TEST(Referee, GameStuckLocalThenGlobal) {
  world::World w(twoVsTwo());
  RefereeConfig cfg;
  cfg.inactive_time = 1e9;  // the robot at the ball stands still: not an inactive call here
  Referee ref(w, test::splRules(), test::twoTeams(), 0, cfg);
  Game& g = ref.game();
  openPlay(w, ref);
  // The ball lies still next to robot 2 (team 1 player 1 at (3, 0)).
  putBall(w, 2.75, 0.05);
  run(w, ref, 30.2);
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::LocalGameStuck);
  // Nobody near it now: after another 30 s, a drop ball.
  putBall(w, 0.0, -2.5);
  run(w, ref, 30.2);
  EXPECT_EQ(count(g, "drop_ball"), 1);
  EXPECT_EQ(g.kickingTeam(), -1);
  EXPECT_EQ(g.state(), gc::State::Ready);  // the drop ball restarts with Ready
}

namespace {

// Sets the ball rolling from where it lies.
void shoot(world::World& w, double vx, double vy) {
  engine::RigidBodyState b = w.ballState();
  b.linear_velocity = Vec3(vx, vy, 0.0);
  b.angular_velocity = Vec3::Zero();
  w.setBallState(b);
}

// A shoot-out kick after Set: the whistle (1 s), the striker's touch, the
// ball rolling at (vx, vy), then `seconds` of play.
void takeKick(world::World& w, Referee& ref, world::RobotId striker, double vx, double vy,
              double seconds) {
  run(w, ref, 1.05);
  ASSERT_EQ(ref.game().state(), gc::State::Playing);
  touchBall(w, ref, striker);
  shoot(w, vx, vy);
  run(w, ref, seconds);
}

}  // namespace

TEST(Referee, ShootoutKicksOnTheRealWorld) {
  world::World w(twoVsTwo());
  RefereeConfig cfg;
  cfg.set_duration = 1.0;
  Referee ref(w, test::splRules(), test::twoTeams(), 0, cfg);
  Game& g = ref.game();
  g.startShootout(0, 2);  // a penalty-kick scenario: two kicks each, team 0 first
  const auto& f = w.field();

  // Kick 1: team 0's player 2 against team 1's keeper (player 1): a goal.
  ref.startShootoutKick(2, 1);
  run(w, ref, 0.02);
  EXPECT_NEAR(w.ballState().pose.translation().x(), 3.2, 1e-3);
  EXPECT_NEAR(w.torsoPose(1).translation().x(), 2.85, 0.05);  // the striker
  EXPECT_NEAR(w.torsoPose(2).translation().x(), 4.45, 0.05);  // the keeper
  for (world::RobotId r : {0, 3})                             // substitutes off the field
    EXPECT_GT(std::abs(w.torsoPose(r).translation().y()), f.halfWidth());
  EXPECT_EQ(g.state(), gc::State::Set);
  takeKick(w, ref, 1, 4.0, 1.7, 2.0);  // towards the left half of the goal, past the keeper
  EXPECT_EQ(g.state(), gc::State::Finished);
  EXPECT_EQ(g.score(0), 1);
  ASSERT_EQ(g.shotOutcomes(0).size(), 1u);
  EXPECT_EQ(g.shotOutcomes(0)[0], ShotOutcome::Goal);

  // Kick 2: team 1's player 2 shoots straight at team 0's keeper: saved.
  ref.startShootoutKick(2, 1);
  takeKick(w, ref, 3, 3.0, 0.0, 6.0);
  EXPECT_EQ(g.state(), gc::State::Finished);
  EXPECT_EQ(g.score(1), 0);
  ASSERT_EQ(g.shotOutcomes(1).size(), 1u);
  EXPECT_EQ(g.shotOutcomes(1)[0], ShotOutcome::Saved);

  // Kick 3: team 1's keeper steps off its line before the kick: goal awarded,
  // and team 1 can no longer catch up (2:0 with one kick left).
  ref.startShootoutKick(2, 1);
  run(w, ref, 1.05);
  ASSERT_EQ(g.state(), gc::State::Playing);
  w.placeRobot(2, 3.9, 0.0, M_PI);
  run(w, ref, 0.05);
  EXPECT_EQ(g.score(0), 2);
  ASSERT_TRUE(g.winner().has_value());
  EXPECT_EQ(*g.winner(), 0);
  EXPECT_EQ(count(g, "game_over"), 1);
}

TEST(Referee, PushingAnOpponentNearTheBallIsAFoul) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  faceOffInOpenPlay(w, ref);
  // Standing face to face without driving: nothing.
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::None);
  // Robot 1 drives into robot 3.
  for (int i = 0; i < 200 && g.penalty(0, 2) == gc::Penalty::None; ++i) {
    w.physics().setRootVelocity(w.robot(1).body, Vec3(0.3, 0.0, 0.0), Vec3::Zero());
    run(w, ref, 0.01);
  }
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::PlayerPushing);
  EXPECT_EQ(g.penalty(1, 2), gc::Penalty::None);  // the pushed robot
  EXPECT_EQ(count(g, "pushing"), 1);
  EXPECT_NEAR(g.penaltyTime(0, 2), 45.0, 0.05);  // the team's first incremental penalty
  run(w, ref, 0.02);                             // removed beyond the touchline
  EXPECT_GT(std::abs(w.torsoPose(1).translation().y()), w.field().halfWidth());
  // The ball was within 0.5 m: a pushing free kick for the other team.
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::PushingFreeKick);
  EXPECT_EQ(g.kickingTeam(), 1);
}

// Robot 1 is driven at `velocity` (world frame), and robot 3 at `other_velocity`, for
// up to `seconds`, until robot 1 is penalised.
// `each_period` runs before each period's drive.
void driveInto(world::World& w, Referee& ref, const Vec3& velocity, double seconds,
               const Vec3& other_velocity = Vec3::Zero(),
               const std::function<void()>& each_period = {}) {
  for (int i = 0;
       i < static_cast<int>(seconds / 0.01) && ref.game().penalty(0, 2) == gc::Penalty::None; ++i) {
    if (each_period) each_period();
    w.physics().setRootVelocity(w.robot(1).body, velocity, Vec3::Zero());
    if (!other_velocity.isZero())
      w.physics().setRootVelocity(w.robot(3).body, other_velocity, Vec3::Zero());
    run(w, ref, 0.01);
  }
}

// At a pushing free kick the ball stays where it is: one still rolling at the call (kicked just
// before it) is stopped there, not left to roll on to the opponents.
TEST(Referee, APushingFreeKickIsTakenWhereTheRollingBallWasAtTheFoul) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  faceOffInOpenPlay(w, ref);
  engine::RigidBodyState rolling = w.ballState();
  rolling.linear_velocity = Vec3(0.0, 1.5, 0.0);  // along the touchline, away from the two
  const Vec3 start = rolling.pose.translation();
  // Kicked again and again from the same place while robot 1 drives into robot 3.
  driveInto(w, ref, Vec3(0.3, 0.0, 0.0), 2.0, Vec3::Zero(), [&] { w.setBallState(rolling); });
  ASSERT_EQ(g.penalty(0, 2), gc::Penalty::PlayerPushing);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::PushingFreeKick);
  run(w, ref, 1.0);
  EXPECT_LT(w.ballState().linear_velocity.norm(), 0.05);
  EXPECT_LT((w.ballState().pose.translation() - start).head<2>().norm(), 0.05)
      << w.ballState().pose.translation().transpose();
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::PushingFreeKick);
}

// Robots 1 and 3 placed at (x, y, yaw), the ball at `ball`, robot 1 driven at
// `velocity` and robot 3 at `other_velocity` for `seconds` (world frame): whether
// that contact was called pushing. The two start apart for longer than a contact's
// gaps, so that it is a new contact.
bool calledPushing(world::World& w, Referee& ref, const Vec3& one, const Vec3& three,
                   const Vec3& ball, const Vec3& velocity, double seconds,
                   const Vec3& other_velocity = Vec3::Zero()) {
  w.placeRobot(1, -1.0, -2.0, 0.0);
  w.placeRobot(3, 1.5, -2.0, M_PI);
  run(w, ref, 0.5);
  const int before = count(ref.game(), "pushing");
  w.placeRobot(1, one.x(), one.y(), one.z());
  w.placeRobot(3, three.x(), three.y(), three.z());
  putBall(w, ball.x(), ball.y());
  driveInto(w, ref, velocity, seconds, other_velocity);
  return count(ref.game(), "pushing") > before;
}

TEST(Referee, FrontToFrontWithTheBallBetweenIsNotPushing) {
  // The rules' exception: two robots going for the ball meet front to front with
  // the ball between them. Robot 1 drives into robot 3, facing it.
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  openPlay(w, ref);
  const Vec3 one(0.45, -2.0, 0.0), three(0.8, -2.0, M_PI), drive(0.3, 0.0, 0.0);
  EXPECT_FALSE(calledPushing(w, ref, one, three, Vec3(0.625, -2.0, 0.0), drive, 2.0));
  // The same drive with the ball away from between them is pushing.
  EXPECT_TRUE(calledPushing(w, ref, one, three, Vec3(0.7, -1.7, 0.0), drive, 2.0));
  EXPECT_EQ(ref.game().penalty(0, 2), gc::Penalty::PlayerPushing);
}

TEST(Referee, SideContactGoingToTheBallIsNotPushing) {
  // The rules' exception: side contact while going to the ball. Robots 1 and 3 walk
  // side by side, robot 3 at robot 1's left; robot 1 veers left into it.
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  openPlay(w, ref);
  const Vec3 one(0.45, -2.0, 0.0), three(0.45, -1.75, 0.0);
  const Vec3 drive(0.25, 0.45, 0.0), alongside(0.25, 0.0, 0.0);
  // The ball ahead of robot 1, where it walks.
  EXPECT_FALSE(calledPushing(w, ref, one, three, Vec3(0.9, -1.35, 0.0), drive, 1.5, alongside));
  // The same walk with the ball behind them: robot 1 is not going to the ball.
  EXPECT_TRUE(calledPushing(w, ref, one, three, Vec3(-0.1, -2.0, 0.0), drive, 1.5, alongside));
  EXPECT_EQ(ref.game().penalty(0, 2), gc::Penalty::PlayerPushing);
}

// The arm links come from the robot's description: for the Nao the shoulder to the
// wrist; for the K1 its upper arms too, which no Nao name matches.
TEST(Referee, ArmLinksAreTheLimbsWithNeitherAFootNorACamera) {
  const auto arms = [](const robots::RobotModel& m) {
    const std::vector<char> arm = referee::armLinks(m);
    std::vector<std::string> names;
    for (size_t l = 0; l < arm.size(); ++l)
      if (arm[l]) names.push_back(m.body->links[l].name);
    return names;
  };
  EXPECT_EQ(arms(robots::loadRobotModel(test::naoH25())),
            (std::vector<std::string>{"LShoulder", "LBiceps", "LElbow", "LForeArm", "LWrist",
                                      "RShoulder", "RBiceps", "RElbow", "RForeArm", "RWrist"}));
  const std::vector<std::string> k1 = arms(robots::loadRobotModel(test::boosterK1()));
  for (const char* link : {"LeftShoulder", "LeftUpperArm", "LeftHand", "RightUpperArm"})
    EXPECT_NE(std::find(k1.begin(), k1.end(), link), k1.end()) << link;
  for (const char* link : {"Trunk", "Head", "LeftFoot", "RightFoot"})
    EXPECT_EQ(std::find(k1.begin(), k1.end(), link), k1.end()) << link;
}

TEST(Referee, BallContactWithAnArm) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  openPlay(w, ref);
  auto ballOnHand = [&](world::RobotId r) {
    const int hand = w.robot(r).model->body->linkIndex("LWrist");
    const engine::Pose p = w.linkPose(r, hand);
    putBall(w, p.translation().x(), p.translation().y() + 0.07, p.translation().z());
    run(w, ref, 0.1);
  };
  // The goalkeeper (player 1) in its own penalty area may.
  ballOnHand(0);
  ASSERT_TRUE(w.lastBallTouch().has_value());
  EXPECT_EQ(w.lastBallTouch()->robot, 0u);
  const std::string link =
      w.robot(0).model->body->links[static_cast<size_t>(w.lastBallTouch()->link)].name;
  EXPECT_TRUE(link == "LWrist" || link == "LForeArm" || link == "LElbow" || link == "LBiceps")
      << link;
  EXPECT_EQ(g.penalty(0, 1), gc::Penalty::None);
  // A field player may not: penalised, the ball put back on the ground there.
  ballOnHand(1);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::IllegalBallContact);
  EXPECT_EQ(count(g, "ball_contact"), 1);
}

namespace {

bool hasEvent(const Game& g, const std::string& type, const std::string& detail) {
  for (const auto& e : g.events())
    if (referee::eventName(e.type) == std::string(type) &&
        e.detail.find(detail) != std::string::npos)
      return true;
  return false;
}

}  // namespace

// A whole (shortened) first half refereed from scripted ball positions on the
// real world: kick-off, a goal, a kick-in, a corner kick, a goal kick.
TEST(Referee, WholeFirstHalfFromScriptedBallPositions) {
  RuleBook rules = test::splRules();
  rules.half_duration = 150.0;  // the rest of the half runs on the clock
  world::World w(twoVsTwo());
  Referee ref(w, rules, test::twoTeams(), 0);
  Game& g = ref.game();
  const auto& f = w.field();
  g.standby();
  g.ready();

  // Kick-off for team 0 (defends -x); the ball is free once team 0 moves it.
  kickOff(w, ref);
  EXPECT_EQ(g.kickingTeam(), 0);
  EXPECT_NEAR(g.secondaryTime(), 10.0, 0.02);
  touchBall(w, ref, 1);
  run(w, ref, 0.05);
  EXPECT_EQ(g.kickingTeam(), -1);

  // A goal for team 0 in the +x goal after a pass (two robots played it):
  // 1:0, Ready with the kick-off for team 1.
  touchBall(w, ref, 0);
  putBall(w, f.halfLength() + 0.3, 0.2);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(g.state(), gc::State::Ready);
  EXPECT_EQ(g.kickingTeam(), 1);
  kickOff(w, ref);
  EXPECT_NEAR(w.ballState().pose.translation().head<2>().norm(), 0.0, 0.01);  // centre mark
  touchBall(w, ref, 3);
  run(w, ref, 0.05);
  EXPECT_EQ(g.kickingTeam(), -1);

  // Team 0 plays it over the touchline: kick-in for team 1 where it left.
  touchBall(w, ref, 1);
  putBall(w, 1.0, f.halfWidth() + 0.2);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::KickIn);
  EXPECT_EQ(g.kickingTeam(), 1);
  EXPECT_NEAR(w.ballState().pose.translation().y(), f.halfWidth(), 1e-3);
  EXPECT_NEAR(w.ballState().pose.translation().x(), 1.0, 0.05);
  touchBall(w, ref, 3);  // team 1 takes it
  run(w, ref, 0.05);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);

  // Team 0's keeper plays it over its own goal line beside the goal: corner for team 1.
  touchBall(w, ref, 0);
  putBall(w, -f.halfLength() - 0.2, 1.5);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::CornerKick);
  EXPECT_EQ(g.kickingTeam(), 1);
  EXPECT_NEAR(w.ballState().pose.translation().x(), -f.halfLength(), 1e-3);
  EXPECT_NEAR(w.ballState().pose.translation().y(), f.halfWidth(), 1e-3);
  // Nobody takes it: the set play ends after its 30 s.
  run(w, ref, 29.9);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::CornerKick);
  run(w, ref, 0.2);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);

  // Team 1 shoots wide of team 0's goal: goal kick for team 0 at the goal area corner.
  touchBall(w, ref, 2);
  putBall(w, -f.halfLength() - 0.2, -1.2);
  run(w, ref, 0.02);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);
  EXPECT_EQ(g.kickingTeam(), 0);
  EXPECT_NEAR(w.ballState().pose.translation().x(), -f.halfLength() + f.goal_area->length, 1e-3);
  EXPECT_NEAR(w.ballState().pose.translation().y(), -0.5 * f.goal_area->width, 1e-3);

  // The half runs out: Finished, 1:0, the events tell the story.
  run(w, ref, g.secondsRemaining() + 0.1);
  EXPECT_EQ(g.state(), gc::State::Finished);
  EXPECT_EQ(g.half(), Half::First);
  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(g.score(1), 0);
  EXPECT_EQ(count(g, "goal"), 1);
  EXPECT_TRUE(hasEvent(g, "set_play", "KICK_IN"));
  EXPECT_TRUE(hasEvent(g, "set_play", "CORNER_KICK"));
  EXPECT_TRUE(hasEvent(g, "set_play", "GOAL_KICK"));
  EXPECT_TRUE(hasEvent(g, "half", "end of the first half"));
  const ControlData d = g.packet(0);
  EXPECT_EQ(d.state, static_cast<uint8_t>(gc::State::Finished));
  EXPECT_EQ(d.first_half, 1);
  EXPECT_EQ(d.teams[0].score, 1);  // team 0 is on the left in the first half
}

TEST(Referee, TheSecondHalfStartsWithEveryRobotInItsNewHalf) {
  // Wherever the first half left them, the robots are put at their start
  // poses turned with the sides as the half-time break begins, and stay there
  // into the second half's Initial.
  RuleBook rules = test::splRules();
  rules.half_duration = 2.0;
  rules.half_time_break = 2.0;
  rules.half_time_to_initial = 1.0;
  world::World w(twoVsTwo());
  Referee ref(w, rules, test::twoTeams(), 0);
  Game& g = ref.game();
  openPlay(w, ref);
  w.placeRobot(0, 2.0, -1.0, 0.5);  // team 0's keeper ends the half in the other half
  for (int i = 0; i < 1000 && g.state() != gc::State::Finished; ++i) run(w, ref, 0.01);
  ASSERT_EQ(g.state(), gc::State::Finished);
  ASSERT_EQ(g.half(), Half::First);
  EXPECT_EQ(count(g, "placement"), 4);
  for (int i = 0; i < 1000 && g.half() != Half::Second; ++i) run(w, ref, 0.01);
  ASSERT_EQ(g.half(), Half::Second);
  ASSERT_EQ(g.state(), gc::State::Initial);
  EXPECT_EQ(g.leftTeam(), 1);
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    const world::RobotPlacement& start = w.scenario().robots[r];
    const engine::Pose torso = w.torsoPose(r);
    const double yaw = std::atan2(torso.linear()(1, 0), torso.linear()(0, 0));
    EXPECT_NEAR(torso.translation().x(), -start.x, 0.02) << "robot " << r;
    EXPECT_NEAR(torso.translation().y(), -start.y, 0.02) << "robot " << r;
    EXPECT_NEAR(std::remainder(yaw - (start.yaw + M_PI), 2 * M_PI), 0.0, 0.02) << "robot " << r;
    // In its own half now: team 1 defends -x.
    EXPECT_LT(torso.translation().x() * (w.robot(r).team == 1 ? 1 : -1), 0.0) << "robot " << r;
  }
  EXPECT_EQ(count(g, "placement"), 4);
}

TEST(Referee, DefendersKeepOutAtKickOffAndAwayAtFreeKicks) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  g.ready();
  kickOff(w, ref);  // team 0 kicks off
  run(w, ref, 0.5);
  EXPECT_EQ(g.penalty(1, 2), gc::Penalty::None);
  w.placeRobot(3, -0.5, 1.0, M_PI);  // team 1 player 2 runs into team 0's half
  run(w, ref, 0.02);
  EXPECT_EQ(g.penalty(1, 2), gc::Penalty::IllegalPosition);
  EXPECT_NEAR(g.penaltyTime(1, 2), 45.0, 0.1);

  g.ballFree();
  putBall(w, 2.0, -2.0);
  run(w, ref, 0.02);
  g.setPlay(gc::SetPlay::PushingFreeKick, 0);
  w.placeRobot(2, 2.4, -2.0, M_PI);  // team 1 player 1, 0.4 m from the ball
  // It has 5 s to leave, and 0.35 m at 0.2 m/s more: 6.75 s.
  run(w, ref, 6.6);
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::None);
  run(w, ref, 0.2);
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::IllegalPosition);
  EXPECT_NEAR(g.penaltyTime(1, 1), 55.0, 0.1);  // the team's second: +10 s
}

TEST(Referee, RefereedRunsAreBitForBitRepeatable) {
  auto play = [] {
    world::World w(twoVsTwo());
    Referee ref(w, test::splRules(), test::twoTeams(), 0);
    Game& g = ref.game();
    openPlay(w, ref);
    faceOff(w);
    for (int i = 0; i < 150; ++i) {
      w.physics().setRootVelocity(w.robot(1).body, Vec3(0.3, 0.0, 0.0), Vec3::Zero());
      run(w, ref, 0.01);
    }
    run(w, ref, 2.0);  // removal to the penalty spot, the free kick
    std::string log;
    for (const auto& e : g.events())
      log += std::to_string(e.time) + referee::eventName(e.type) + e.detail + ";";
    return std::make_pair(w.stateHash(), log);
  };
  const auto a = play(), b = play();
  EXPECT_EQ(a.first, b.first);
  EXPECT_EQ(a.second, b.second);
  EXPECT_NE(a.second.find("pushing"), std::string::npos);
}

TEST(Referee, IndirectKickDirectGoalBecomesAGoalKickOwnGoalsCount) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  const auto& f = w.field();
  g.ready();
  kickOff(w, ref);
  touchBall(w, ref, 1);  // team 0 player 2 takes the kick-off ...
  run(w, ref, 0.05);
  putBall(w, f.halfLength() + 0.3, -0.3);  // ... and scores directly
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 0);
  EXPECT_EQ(count(g, "goal_disallowed"), 1);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);
  EXPECT_EQ(g.kickingTeam(), 1);
  EXPECT_NEAR(w.ballState().pose.translation().x(), f.halfLength() - f.goal_area->length, 1e-3);
  EXPECT_NEAR(w.ballState().pose.translation().y(), -0.5 * f.goal_area->width, 1e-3);
  // Team 1 takes the goal kick; then its keeper puts the ball into its own goal: it counts.
  touchBall(w, ref, 3);
  run(w, ref, 0.05);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::None);
  touchBall(w, ref, 2);
  putBall(w, f.halfLength() + 0.3, 0.3);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 1);
  // Team 1 kicks off (the referee's whistle) and scores straight from it: the
  // touches of its two robots before the goal do not count any more.
  kickOff(w, ref);
  touchBall(w, ref, 3);
  putBall(w, -f.halfLength() - 0.3, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(1), 0);
  EXPECT_EQ(count(g, "goal_disallowed"), 2);

  // The simleague rule book scores directly.
  world::World w2(twoVsTwo());
  Referee ref2(w2, loadRuleBook(test::sourceDir() / "configs" / "rules" / "simleague.yaml"),
               test::twoTeams(), 0);
  ref2.game().ready();
  kickOff(w2, ref2);
  touchBall(w2, ref2, 1);
  putBall(w2, w2.field().halfLength() + 0.3, 0.0);
  run(w2, ref2, 0.02);
  EXPECT_EQ(ref2.game().score(0), 1);
}

namespace {

// 3 v 3: twoVsTwo's robots 0-3 and a third of each team (robots 4 and 5).
world::Scenario threeVsThree() {
  world::Scenario s = twoVsTwo();
  for (int team = 0; team < 2; ++team) {
    world::RobotPlacement p;
    p.team = team;
    p.number = 3;
    p.x = team == 0 ? -2.0 : 2.0;
    p.y = -1.0;
    p.yaw = team == 0 ? 0.0 : M_PI;
    s.robots.push_back(p);
  }
  return s;
}

std::string lastDetail(const Game& g, EventType type) {
  std::string d;
  for (const auto& e : g.events())
    if (e.type == type) d = e.detail;
  return d;
}

}  // namespace

TEST(Referee, HslKickOffScoresOnlyAfterASecondTouchOrTheKickerOutsideTheCircle) {
  // Two robots a team: the kicker must play the ball outside the centre circle before a goal.
  for (const bool outside : {false, true}) {
    KickedOff game(hslRules());
    auto& [w, ref, g] = game;
    w.placeRobot(1, -0.35, 0.0, 0.0);  // team 0 player 2 at the centre mark takes the kick-off
    touchBall(w, ref, 1);
    if (outside) {
      w.placeRobot(1, -1.5, 1.0, 0.0);  // ... and plays the ball again outside the circle
      touchBall(w, ref, 1);
    }
    putBall(w, w.field().halfLength() + 0.3, -0.3);
    run(w, ref, 0.02);
    EXPECT_EQ(g.score(0), outside ? 1 : 0) << outside;
    if (outside) continue;
    EXPECT_EQ(count(g, "goal_disallowed"), 1);
    EXPECT_NE(lastDetail(g, EventType::GoalDisallowed).find("outside the centre circle"),
              std::string::npos);
    EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);
    EXPECT_EQ(g.kickingTeam(), 1);
  }
  // Three robots a team: two different robots must touch the ball.
  for (const bool second : {false, true}) {
    KickedOff game(hslRules(), threeVsThree());
    auto& [w, ref, g] = game;
    touchBall(w, ref, 1);              // outside the circle, but alone
    if (second) touchBall(w, ref, 4);  // team 0 player 3
    putBall(w, w.field().halfLength() + 0.3, 0.3);
    run(w, ref, 0.02);
    EXPECT_EQ(g.score(0), second ? 1 : 0) << second;
    if (!second) {
      EXPECT_NE(lastDetail(g, EventType::GoalDisallowed).find("two different robots"),
                std::string::npos);
    }
  }
  // A rule book without the HSL's kick-off rule (the 3D league's) scores straight from it.
  KickedOff game(loadRuleBook(test::sourceDir() / "configs" / "rules" / "simleague.yaml"));
  auto& [w, ref, g] = game;
  w.placeRobot(1, -0.35, 0.0, 0.0);
  touchBall(w, ref, 1);
  putBall(w, w.field().halfLength() + 0.3, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(ref.game().score(0), 1);  // the 3D league scores straight from the kick-off
}

TEST(Referee, HslKickInIsIndirectAndAFreeKickIntoTheOwnGoalIsACorner) {
  world::World w(twoVsTwo());
  Referee ref(w, hslRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  const auto& f = w.field();
  kickInForTeam0(w, ref);
  if (HasFatalFailure()) return;
  touchBall(w, ref, 1);  // team 0 takes it and scores straight from it
  putBall(w, f.halfLength() + 0.3, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 0);
  EXPECT_NE(lastDetail(g, EventType::GoalDisallowed).find("kick-in"), std::string::npos);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);  // for the defenders
  ASSERT_EQ(g.kickingTeam(), 1);
  // Team 1 takes its goal kick straight into its own goal (+x): a corner kick for team 0.
  touchBall(w, ref, 3);
  putBall(w, f.halfLength() + 0.3, 0.5);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 0);
  EXPECT_NE(lastDetail(g, EventType::GoalDisallowed).find("own goal straight from a free kick"),
            std::string::npos);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::CornerKick);
  EXPECT_EQ(g.kickingTeam(), 0);
  EXPECT_NEAR(w.ballState().pose.translation().x(), f.halfLength(), 1e-3);
  EXPECT_NEAR(w.ballState().pose.translation().y(), f.halfWidth(), 1e-3);
  // A corner kick is direct.
  touchBall(w, ref, 0);
  putBall(w, f.halfLength() + 0.3, -0.2);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 1);
  // After team 1's kick-off, a kick-in for team 1 touched by another robot (an opponent) scores.
  kickOff(w, ref);
  g.ballFree();
  touchBall(w, ref, 0);
  putBall(w, -1.0, -f.halfWidth() - 0.2);
  run(w, ref, 0.02);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::KickIn);
  ASSERT_EQ(g.kickingTeam(), 1);
  touchBall(w, ref, 3);
  touchBall(w, ref, 1);  // team 0's robot deflects it ...
  touchBall(w, ref, 3);  // ... and team 1 scores
  putBall(w, -f.halfLength() - 0.3, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(1), 1);
}

TEST(Referee, HslFreeKickDistanceIsTheCentreCircleAndAGoalKickClearsThePenaltyArea) {
  world::Scenario s = twoVsTwo();
  s.field_file = test::sourceDir() / "fields" / "hsl_m.yaml";  // centre circle 1.475 m
  for (const bool hsl : {true, false}) {
    world::World w(s);
    Referee ref(w, hsl ? hslRules() : test::splRules(), test::twoTeams(), 0);
    Game& g = ref.game();
    const auto& f = w.field();
    openPlay(w, ref);
    putBall(w, 2.0, -2.0);
    run(w, ref, 0.02);
    g.setPlay(gc::SetPlay::PushingFreeKick, 0);
    run(w, ref, 0.02);                 // awarded, then
    w.placeRobot(2, 3.2, -2.0, M_PI);  // team 1 player 1 walks to 1.2 m from the ball
    run(w, ref, 5.1);
    EXPECT_EQ(g.penalty(1, 1), hsl ? gc::Penalty::IllegalPosition : gc::Penalty::None) << hsl;
    g.ballFree();
    // Team 1's goal kick at its goal-area corner; team 0 player 2 in team 1's penalty area,
    // 2.9 m from the ball.
    const double corner_x = f.halfLength() - f.goal_area->length;
    putBall(w, corner_x, 0.5 * f.goal_area->width);
    run(w, ref, 0.02);
    w.placeRobot(1, corner_x - 0.6, -0.9, 0.0);
    g.setPlay(gc::SetPlay::GoalKick, 1);
    // Inside when it was awarded, 1.4 m from the area's front edge: 5 s and 1.4 m at 0.2 m/s.
    run(w, ref, 11.9);
    EXPECT_EQ(g.penalty(0, 2), gc::Penalty::None);
    run(w, ref, 0.2);
    EXPECT_EQ(g.penalty(0, 2), hsl ? gc::Penalty::IllegalPosition : gc::Penalty::None) << hsl;
    if (hsl) {
      EXPECT_NE(lastDetail(g, EventType::IllegalPosition).find("penalty area"), std::string::npos);
    }
  }
}

TEST(Referee, AnInGamePenaltyKickScoresDirectlyUnderTheTwoTouchRule) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  openPlay(w, ref);
  g.setPlay(gc::SetPlay::PenaltyKick, 0);
  kickOff(w, ref);  // Ready, Set, the whistle
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::PenaltyKick);
  touchBall(w, ref, 1);  // the kick: the ball moves, the set play is over ...
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);
  putBall(w, w.field().halfLength() + 0.3, 0.0);  // ... and it goes in
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(count(g, "goal_disallowed"), 0);
}

TEST(Referee, HslRestartsEndWithTheirKickAndStartAgainWithEachAward) {
  // A kick-in team 0 never takes (its 45 s run out): a goal its robot scores alone later counts.
  {
    world::World w(twoVsTwo());
    Referee ref(w, hslRules(), test::twoTeams(), 0);
    Game& g = ref.game();
    const auto& f = w.field();
    kickInForTeam0(w, ref);
    if (HasFatalFailure()) return;
    run(w, ref, 45.1);
    ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::None);
    touchBall(w, ref, 1);
    putBall(w, f.halfLength() + 0.3, 0.0);
    run(w, ref, 0.02);
    EXPECT_EQ(g.score(0), 1);
  }
  // Team 1's goal kick, team 0's robot plays the ball over team 1's goal line again: a new goal
  // kick (the same set play for the same team); team 1 kicks it straight into its own goal: a
  // corner kick (the first goal kick's touch by team 0 does not count any more).
  world::World w(twoVsTwo());
  Referee ref(w, hslRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  const auto& f = w.field();
  openPlay(w, ref);
  touchBall(w, ref, 1);
  putBall(w, f.halfLength() + 0.3, 2.0);  // wide of the goal
  run(w, ref, 0.02);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);
  touchBall(w, ref, 1);
  putBall(w, f.halfLength() + 0.3, -2.0);
  run(w, ref, 0.02);
  ASSERT_EQ(g.currentSetPlay(), gc::SetPlay::GoalKick);
  ASSERT_EQ(g.kickingTeam(), 1);
  run(w, ref, 0.02);
  touchBall(w, ref, 3);
  putBall(w, f.halfLength() + 0.3, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 0);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::CornerKick);
}

TEST(Referee, HslGoalKickAreaIsTheKickingTeamsInEitherHalf) {
  // Team 0's goal kick at the -x goal (first half), then in the second half at the +x goal: a
  // robot of team 1 in team 0's penalty area is penalised, one in its own is not.
  RuleBook rules = hslRules();
  rules.half_duration = 8.0;  // short halves (long enough for the goal kick)
  rules.half_time_break = 2.0;
  rules.half_time_to_initial = 1.0;
  for (const bool second_half : {false, true}) {
    world::World w(twoVsTwo());
    Referee ref(w, rules, test::twoTeams(), 0);
    Game& g = ref.game();
    const auto& f = w.field();
    if (second_half) {
      openPlay(w, ref);
      for (int i = 0; i < 1000 && g.half() != Half::Second; ++i) run(w, ref, 0.01);
      ASSERT_EQ(g.state(), gc::State::Initial);
      ASSERT_EQ(g.leftTeam(), 1);  // team 0 defends +x now
    }
    g.ready();
    kickOff(w, ref);
    g.ballFree();
    const double side = second_half ? 1.0 : -1.0;  // team 0's goal
    const double front = f.halfLength() - f.penalty_area.value().length;
    putBall(w, side * (f.halfLength() - f.goal_area->length), 0.5 * f.goal_area->width);
    run(w, ref, 0.02);
    g.setPlay(gc::SetPlay::GoalKick, 0);
    run(w, ref, 0.02);
    w.placeRobot(3, side * (front + 0.3), -1.0, 0.0);  // team 1 player 2, in team 0's area
    w.placeRobot(2, -side * (front + 0.3), 1.0, 0.0);  // team 1 player 1, in its own area
    run(w, ref, 5.1);
    EXPECT_EQ(g.penalty(1, 2), gc::Penalty::IllegalPosition) << second_half;
    EXPECT_EQ(g.penalty(1, 1), gc::Penalty::None) << second_half;
  }
}

TEST(Referee, ASavedPenaltyKickIsAFailedOneUnderTheTwoTouchRule) {
  world::World w(twoVsTwo());
  Referee ref(w, test::splRules(), test::twoTeams(), 0);
  Game& g = ref.game();
  openPlay(w, ref);
  g.setPlay(gc::SetPlay::PenaltyKick, 0);
  kickOff(w, ref);
  touchBall(w, ref, 1);  // the kick ...
  touchBall(w, ref, 2);  // ... team 1's keeper saves it ...
  touchBall(w, ref, 1);  // ... and the kicker scores from the rebound: refused
  putBall(w, w.field().halfLength() + 0.3, 0.0);
  run(w, ref, 0.02);
  EXPECT_EQ(g.score(0), 0);
  EXPECT_EQ(count(g, "goal_disallowed"), 1);
}
