// The game-state machine on simulated time, against the rules (spl-rules.md
// sections 3-5) and the GameController packet it produces.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "referee_support.hpp"
#include "simsoccer/engine/config.hpp"
#include "simsoccer/referee/game.hpp"
#include "simsoccer/referee/gamecontroller_link.hpp"

using namespace simsoccer;
using namespace simsoccer::referee;

namespace {

// Advances in 10 ms steps, as the simulator does.
void run(Game& g, double seconds) {
  for (int i = 0; i < static_cast<int>(std::lround(seconds / 0.01)); ++i) g.advance(0.01);
}

}  // namespace

TEST(Game, KickOffFlowAndTheHalfClockStartsAtTheKickOff) {
  Game g(test::splRules(), test::twoTeams(), 0);
  EXPECT_EQ(g.state(), gc::State::Initial);
  run(g, 20);  // Initial: nothing runs
  EXPECT_DOUBLE_EQ(g.secondsRemaining(), 600);
  g.standby();
  g.ready();
  EXPECT_EQ(g.kickingTeam(), 0);
  run(g, 44.9);
  EXPECT_EQ(g.state(), gc::State::Ready);
  run(g, 0.2);  // Ready ends by itself after 45 s
  EXPECT_EQ(g.state(), gc::State::Set);
  EXPECT_DOUBLE_EQ(g.secondsRemaining(), 600);  // not before the half's first kick-off
  g.playing();
  EXPECT_NEAR(g.secondaryTime(), 10, 1e-9);  // kick-off: ball free after 10 s
  run(g, 5);
  EXPECT_EQ(g.kickingTeam(), 0);
  run(g, 5.1);
  EXPECT_EQ(g.kickingTeam(), -1);  // ball free
  EXPECT_NEAR(g.secondsRemaining(), 600 - 10.1, 1e-6);
}

TEST(Game, GoalGivesTheKickOffToTheOtherTeamAndReadySetCountAfterwards) {
  Game g(test::splRules(), test::twoTeams(), 0);
  g.ready();
  g.set();
  g.playing();
  run(g, 30);
  g.goal(0);
  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(g.state(), gc::State::Ready);
  EXPECT_EQ(g.kickingTeam(), 1);
  const double before = g.secondsRemaining();
  run(g, 20);  // round robin: Ready counts as playing time after the first kick-off
  EXPECT_NEAR(g.secondsRemaining(), before - 20, 1e-6);
  g.set();
  g.playing();
  EXPECT_EQ(g.kickingTeam(), 1);
}

TEST(Game, SetPlaysEndAfterTheirTimeOrWhenTheBallIsFree) {
  Game g(test::splRules(), test::twoTeams(), 0);
  g.ready();
  g.set();
  g.playing();
  g.ballFree();
  g.setPlay(gc::SetPlay::KickIn, 1);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::KickIn);
  EXPECT_EQ(g.kickingTeam(), 1);
  run(g, 29.9);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::KickIn);
  run(g, 0.2);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);
  g.setPlay(gc::SetPlay::CornerKick, 0);
  run(g, 3);
  g.ballFree();  // the kicking team moved the ball
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);
  // A penalty kick goes through Ready (30 s) and Set, then 30 s in Playing.
  g.setPlay(gc::SetPlay::PenaltyKick, 1);
  EXPECT_EQ(g.state(), gc::State::Ready);
  run(g, 30.1);
  EXPECT_EQ(g.state(), gc::State::Set);
  g.playing();
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::PenaltyKick);
  run(g, 30.1);
  EXPECT_EQ(g.currentSetPlay(), gc::SetPlay::None);
}

TEST(Game, PenaltiesGrowByTheTeamsIncrementAndRunOnlyInReadyAndPlaying) {
  Game g(test::splRules(), test::twoTeams(), 0);
  g.ready();
  g.penalise(0, 2, gc::Penalty::PlayerPushing);
  EXPECT_DOUBLE_EQ(g.penaltyTime(0, 2), 45);
  g.penalise(0, 3, gc::Penalty::LeavingTheField);
  EXPECT_DOUBLE_EQ(g.penaltyTime(0, 3), 55);  // 45 + 10 for the team's earlier one
  g.penalise(0, 4, gc::Penalty::InactivePlayer);
  EXPECT_DOUBLE_EQ(g.penaltyTime(0, 4), 45);  // not incremental
  g.penalise(1, 2, gc::Penalty::IllegalBallContact);
  EXPECT_DOUBLE_EQ(g.penaltyTime(1, 2), 45);  // the other team's count is its own
  g.penalise(0, 5, gc::Penalty::IllegalPosition);
  EXPECT_DOUBLE_EQ(g.penaltyTime(0, 5), 65);
  run(g, 10);  // Ready: timers run
  EXPECT_NEAR(g.penaltyTime(0, 2), 35, 1e-6);
  g.set();
  g.penalise(0, 1, gc::Penalty::IllegalPositionInSet);
  EXPECT_DOUBLE_EQ(g.penaltyTime(0, 1), 15);
  run(g, 10);  // Set: frozen
  EXPECT_NEAR(g.penaltyTime(0, 2), 35, 1e-6);
  EXPECT_DOUBLE_EQ(g.penaltyTime(0, 1), 15);
  g.playing();
  run(g, 15.05);  // lifted when the time is up
  EXPECT_EQ(g.penalty(0, 1), gc::Penalty::None);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::PlayerPushing);
  run(g, 20);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::None);
  int lifted = 0;
  for (const auto& e : g.events()) lifted += e.type == referee::EventType::Unpenalise;
  EXPECT_GE(lifted, 2);
  EXPECT_EQ(lifted, 4);                                 // four of the five penalties have run out
  EXPECT_EQ(g.penalty(0, 6), gc::Penalty::Substitute);  // numbers beyond the 5 players

  // A request for pick-up replaces a running penalty and keeps its timer, at least 45 s.
  g.penalise(1, 3, gc::Penalty::PlayerPushing);  // incremental: more than 45 s
  run(g, 2);
  const double left = g.penaltyTime(1, 3);
  ASSERT_GT(left, 45.0);
  g.penalise(1, 3, gc::Penalty::RequestForPickup);
  EXPECT_EQ(g.penalty(1, 3), gc::Penalty::RequestForPickup);
  EXPECT_NEAR(g.penaltyTime(1, 3), left, 1e-9);
  g.penalise(1, 4, gc::Penalty::IllegalMotionInSet);  // 15 s
  g.penalise(1, 4, gc::Penalty::RequestForPickup);
  EXPECT_NEAR(g.penaltyTime(1, 4), 45.0, 1e-9);
}

TEST(Game, HalfTimeSwapsSidesAndTheOtherTeamKicksOff) {
  Game g(test::splRules(), test::twoTeams(), 0);
  EXPECT_EQ(g.packet(0).teams[0].team_number, 13);  // team 0 on the operator's left
  g.ready();
  g.set();
  g.playing();
  g.penalise(1, 1, gc::Penalty::PlayerPushing);
  run(g, 600.05);
  EXPECT_EQ(g.state(), gc::State::Finished);
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::None);  // penalties end with the half
  EXPECT_EQ(g.half(), Half::First);
  run(g, 299);
  EXPECT_EQ(g.state(), gc::State::Finished);
  run(g, 1.1);  // 5 min into the break: Initial of the second half
  EXPECT_EQ(g.state(), gc::State::Initial);
  EXPECT_EQ(g.half(), Half::Second);
  EXPECT_EQ(g.kickingTeam(), 1);
  const ControlData d = g.packet(1);
  EXPECT_EQ(d.first_half, 0);
  EXPECT_EQ(d.teams[0].team_number, 5);  // swapped
  EXPECT_EQ(d.teams[1].team_number, 13);
  EXPECT_EQ(d.secs_remaining, 600);
  // The break's timer runs on in the second half's Initial (GameController3), and past 0.
  EXPECT_EQ(d.secondary_time, 300);  // 600 - 300.15 s, rounded up
  run(g, 100.0);
  EXPECT_EQ(g.packet(2).secondary_time, 200);
  run(g, 250.0);
  EXPECT_EQ(g.packet(3).secondary_time, -50);  // the break is over: counting below 0
  g.ready();
  EXPECT_EQ(g.packet(4).secondary_time, 45);  // Ready's countdown
  g.set();
  g.playing();
  run(g, 600.05);
  EXPECT_TRUE(g.gameOver());
}

TEST(Game, MercyRuleEndsTheGame) {
  Game g(test::splRules(), test::twoTeams(), 0);
  g.ready();
  g.set();
  g.playing();
  for (int i = 0; i < 10; ++i) {
    g.goal(1);
    if (g.gameOver()) break;
    g.set();
    g.playing();
  }
  EXPECT_EQ(g.score(1), 10);
  EXPECT_TRUE(g.gameOver());
  EXPECT_EQ(g.state(), gc::State::Finished);
}

TEST(Game, TimeoutsSubstitutesAndDropBall) {
  Game g(test::splRules(), test::twoTeams(), 0);
  g.timeout(1);  // a team timeout: the other team gets the kick-off
  EXPECT_EQ(g.phase(), gc::GamePhase::Timeout);
  EXPECT_EQ(g.kickingTeam(), 0);
  EXPECT_THROW(g.timeout(1), std::logic_error);  // one per game
  g.ready();
  EXPECT_EQ(g.phase(), gc::GamePhase::Normal);
  g.set();
  g.playing();
  g.dropBall();
  EXPECT_EQ(g.state(), gc::State::Ready);
  EXPECT_EQ(g.kickingTeam(), -1);
  EXPECT_EQ(g.packet(0).kicking_team, gc::kKickingTeamNone);
  g.set();
  g.playing();
  EXPECT_DOUBLE_EQ(g.secondaryTime(), 0);  // a drop ball is in play at once
  g.substitute(0, 2, 6);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::Substitute);
  EXPECT_EQ(g.penalty(0, 6), gc::Penalty::None);
}

TEST(Game, PacketCarriesTheState) {
  Game g(test::splRules(), test::twoTeams(), 1);
  g.ready();
  run(g, 12.3);
  g.penalise(1, 3, gc::Penalty::PlayerPushing);
  run(g, 0.5);
  const ControlData d = g.packet(7);
  EXPECT_EQ(d.packet_number, 7);
  EXPECT_EQ(d.state, static_cast<uint8_t>(gc::State::Ready));
  EXPECT_EQ(d.kicking_team, 5);     // team numbers, not indices
  EXPECT_EQ(d.secondary_time, 33);  // 45 - 12.8 = 32.2, rounded up
  EXPECT_EQ(d.players_per_team, 5);
  EXPECT_EQ(d.teams[1].players[2].penalty, static_cast<uint8_t>(gc::Penalty::PlayerPushing));
  EXPECT_EQ(d.teams[1].players[2].secs_till_unpenalised, 45);  // 44.5 rounded up
  // Byte-exact on the wire.
  const auto bytes = encode(d);
  EXPECT_EQ(decodeControl(bytes), d);
}

TEST(Game, RuleBookErrorsNameTheKey) {
  const test::TempDir dir("rules");
  std::ifstream in(test::sourceDir() / "configs" / "rules" / "spl.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  text.replace(text.find("half_duration: 600"), 18, "half_duration: -5");
  std::ofstream(dir / "bad.yaml") << text;
  try {
    loadRuleBook(dir / "bad.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "half_duration");
  }
  EXPECT_NO_THROW(loadRuleBook(test::sourceDir() / "configs" / "rules" / "simleague.yaml"));
  // The restarts' and the fallen robots' rules: a bad value names its key.
  const auto refusedAt = [&](const std::string& from, const std::string& to) -> std::string {
    std::ifstream hsl(test::sourceDir() / "configs" / "rules" / "hsl_middle_advanced.yaml");
    std::string t((std::istreambuf_iterator<char>(hsl)), std::istreambuf_iterator<char>());
    EXPECT_NE(t.find(from), std::string::npos) << from;
    t.replace(t.find(from), from.size(), to);
    std::ofstream(dir / "bad.yaml") << t;
    try {
      loadRuleBook(dir / "bad.yaml");
    } catch (const engine::ConfigError& e) {
      return e.key();
    }
    return "";
  };
  EXPECT_EQ(refusedAt("free_kick_distance: centre_circle", "free_kick_distance: centre"),
            "restarts.free_kick_distance");
  EXPECT_EQ(refusedAt("free_kick_distance: centre_circle", "free_kick_distance: -1"),
            "restarts.free_kick_distance");
  EXPECT_EQ(refusedAt("goal_kick_avoidance: penalty_area", "goal_kick_avoidance: goal_area"),
            "restarts.goal_kick_avoidance");
  EXPECT_EQ(refusedAt("free_kick_own_goal: corner_kick", "free_kick_own_goal: corner"),
            "restarts.free_kick_own_goal");
  EXPECT_EQ(refusedAt("get_up_attempts: 3", "get_up_attempts: 0"), "fallen.get_up_attempts");
  EXPECT_EQ(refusedAt("fallen: {time: 20", "fallen: {time: 0"), "fallen.time");
  EXPECT_EQ(refusedAt("free_kick_distance: centre_circle", "free_kick_distance: 1.5"), "");
  const RuleBook hsl =
      loadRuleBook(test::sourceDir() / "configs" / "rules" / "hsl_middle_advanced.yaml");
  EXPECT_FALSE(hsl.kick_off_direct_goal);
  EXPECT_TRUE(hsl.kick_in_indirect && hsl.free_kick_own_goal_corner &&
              hsl.free_kick_distance_centre_circle && hsl.goal_kick_clears_penalty_area);
  EXPECT_EQ(hsl.fallen_time, 20.0);
  EXPECT_EQ(hsl.get_up_attempts, 3);
  const RuleBook spl = test::splRules();
  EXPECT_TRUE(spl.kick_off_direct_goal);
  EXPECT_FALSE(spl.kick_in_indirect || spl.free_kick_own_goal_corner ||
               spl.free_kick_distance_centre_circle || spl.goal_kick_clears_penalty_area);
  EXPECT_EQ(spl.free_kick_distance, 0.75);
  EXPECT_EQ(spl.fallen_time, 10.0);
  EXPECT_EQ(spl.get_up_attempts, 2);
}

namespace {

// Plays both halves without goals: a drawn game, over.
Game drawnGame() {
  Game g(test::splRules(), test::twoTeams(), 0);
  for (int half = 0; half < 2; ++half) {
    g.ready();
    run(g, 45.1);
    g.playing();
    run(g, 600.5);
    if (half == 0) run(g, 300.1);  // half-time: Initial of the second half
  }
  return g;
}

// One shoot-out kick from the whistle to its end.
void kick(Game& g, ShotOutcome outcome, int striker = 2, int keeper = 1) {
  g.shootoutKick(striker, keeper);
  g.playing();
  if (outcome == ShotOutcome::Goal)
    g.goal(g.kickingTeam());
  else
    g.finishShot(outcome);
}

}  // namespace

TEST(Game, ShootoutAfterADrawIsDecidedWhenATeamCanNoLongerCatchUp) {
  Game g = drawnGame();
  ASSERT_TRUE(g.gameOver());
  ASSERT_FALSE(g.winner().has_value());
  g.startShootout(1);
  EXPECT_EQ(g.phase(), gc::GamePhase::PenaltyShoot);
  EXPECT_EQ(g.state(), gc::State::Initial);
  EXPECT_FALSE(g.gameOver());
  EXPECT_THROW(g.ready(), std::logic_error);
  EXPECT_THROW(g.timeout(0), std::logic_error);

  g.shootoutKick(3, 1);  // team 1 shoots first
  EXPECT_EQ(g.state(), gc::State::Set);
  EXPECT_EQ(g.kickingTeam(), 1);
  EXPECT_EQ(g.penalty(1, 3), gc::Penalty::None);
  EXPECT_EQ(g.penalty(0, 1), gc::Penalty::None);  // the keeper
  EXPECT_EQ(g.penalty(1, 1), gc::Penalty::Substitute);
  EXPECT_EQ(g.penalty(0, 2), gc::Penalty::Substitute);
  g.playing();
  g.goal(1);  // 1:0 for team 1
  EXPECT_EQ(g.state(), gc::State::Finished);
  kick(g, ShotOutcome::Saved);  // team 0
  kick(g, ShotOutcome::Goal);   // team 1: 2:0
  EXPECT_FALSE(g.winner().has_value());
  kick(g, ShotOutcome::Wide);  // team 0: 0 goals, one kick left, cannot catch up
  ASSERT_TRUE(g.winner().has_value());
  EXPECT_EQ(*g.winner(), 1);
  EXPECT_TRUE(g.gameOver());
  EXPECT_THROW(g.shootoutKick(2, 1), std::logic_error);

  const ControlData d = g.packet(0);
  EXPECT_EQ(d.game_phase, static_cast<uint8_t>(gc::GamePhase::PenaltyShoot));
  EXPECT_EQ(d.state, static_cast<uint8_t>(gc::State::Finished));
  // teams[0] swapped at half-time (team 1 on the left) and then before kicks
  // 2, 3 and 4 (GC3 flips sides for every kick after the first): team 0 now.
  EXPECT_EQ(d.teams[0].team_number, 13);
  EXPECT_EQ(d.teams[0].score, 0);
  EXPECT_EQ(d.teams[0].penalty_shot, 2);
  EXPECT_EQ(d.teams[0].single_shots, 0);
  EXPECT_EQ(d.teams[1].team_number, 5);
  EXPECT_EQ(d.teams[1].score, 2);
  EXPECT_EQ(d.teams[1].penalty_shot, 2);
  EXPECT_EQ(d.teams[1].single_shots, 0b11);
}

TEST(Game, ShootoutSuddenDeathRanksTheKicks) {
  Game g(test::splRules(), test::twoTeams(), 0);
  g.startShootout(0);  // stand-alone, the rule book's 3 kicks
  for (int i = 0; i < 3; ++i) {
    kick(g, i == 0 ? ShotOutcome::Goal : ShotOutcome::Saved);  // team 0
    kick(g, i == 2 ? ShotOutcome::Goal : ShotOutcome::Wide);   // team 1
  }
  EXPECT_EQ(g.score(0), 1);
  EXPECT_EQ(g.score(1), 1);
  EXPECT_FALSE(g.winner().has_value());
  // Round 1: both saved -> again. Round 2: wide beats nothing; saved beats wide.
  kick(g, ShotOutcome::Saved);
  kick(g, ShotOutcome::Saved);
  EXPECT_FALSE(g.winner().has_value());
  kick(g, ShotOutcome::Wide);
  EXPECT_FALSE(g.winner().has_value());  // team 1 always gets its kick
  kick(g, ShotOutcome::Saved);
  ASSERT_TRUE(g.winner().has_value());
  EXPECT_EQ(*g.winner(), 1);
  EXPECT_EQ(g.shotsTaken(0), 5);
  EXPECT_EQ(g.shotsTaken(1), 5);
}

TEST(Game, ShootoutCoinAfterTheLastSuddenDeathRoundIsSeeded) {
  auto play = [](uint64_t seed) {
    Game g(test::splRules(), test::twoTeams(), 0);
    g.startShootout(0, 1, seed);  // one regular kick each
    for (int i = 0; i < 2 * (1 + 3); ++i) kick(g, ShotOutcome::Post);
    EXPECT_TRUE(g.gameOver());
    EXPECT_EQ(g.events().back().detail.find("coin toss") != std::string::npos, true);
    return *g.winner();
  };
  int wins0 = 0;
  for (uint64_t seed = 0; seed < 16; ++seed) {
    const int w = play(seed);
    EXPECT_EQ(w, play(seed));  // the same seed, the same coin
    wins0 += w == 0;
  }
  EXPECT_GT(wins0, 0);  // both sides of the coin come up
  EXPECT_LT(wins0, 16);
}

TEST(Game, ShotClockRunsOnlyInPlayingAndEndsTheKick) {
  RuleBook r = test::splRules();
  r.sudden_death = false;
  Game g(r, test::twoTeams(), 0);
  g.startShootout(0, 2);
  g.shootoutKick(2, 1);
  run(g, 10);
  EXPECT_DOUBLE_EQ(g.secondsRemaining(), 30);  // Set: frozen
  EXPECT_EQ(g.packet(0).secs_remaining, 30);
  g.playing();
  run(g, 29.9);
  EXPECT_EQ(g.state(), gc::State::Playing);
  run(g, 0.2);
  EXPECT_EQ(g.state(), gc::State::Finished);
  EXPECT_EQ(g.shotOutcomes(0).back(), ShotOutcome::NoKick);
  g.shootoutKick(4, 1);  // team 1
  g.playing();
  g.shotKicked();
  run(g, 30.1);
  EXPECT_EQ(g.shotOutcomes(1).back(), ShotOutcome::Other);
  kick(g, ShotOutcome::Goal);
  kick(g, ShotOutcome::Goal);
  // 1:1 after two kicks each and no sudden death in this rule book: a draw.
  EXPECT_TRUE(g.gameOver());
  EXPECT_FALSE(g.winner().has_value());
  // Not from the middle of a game.
  Game h(test::splRules(), test::twoTeams(), 0);
  h.ready();
  EXPECT_THROW(h.startShootout(0), std::logic_error);
}

TEST(GameControllerLink, BroadcastsAt2HzOfSimTimeAndTakesReturnPackets) {
  UdpReceiver robot(0, "127.0.0.1");  // a robot listening for the GameController
  GameControllerLinkConfig cfg;
  cfg.address = "127.0.0.1";
  cfg.control_port = robot.port();
  cfg.return_port = 0;
  cfg.return_bind = "127.0.0.1";
  GameControllerLink link(cfg);
  Game g(test::splRules(), test::twoTeams(), 0);
  g.ready();
  for (int i = 0; i < 200; ++i) {  // 2 s in 10 ms control periods
    g.advance(0.01);
    link.update(g);
  }
  EXPECT_EQ(link.packetsSent(), 4u);  // t = 0.01, 0.51, 1.01, 1.51
  std::array<uint8_t, 512> buf{};
  for (uint8_t n = 0; n < 4; ++n) {
    const size_t size = robot.receive(buf, 2.0);
    ASSERT_EQ(size, kControlSize);
    const ControlData d = decodeControl(std::span<const uint8_t>(buf.data(), size));
    EXPECT_EQ(d.packet_number, n);
    EXPECT_EQ(d.state, static_cast<uint8_t>(gc::State::Ready));
    EXPECT_EQ(d.kicking_team, 13);
    EXPECT_EQ(d.secondary_time, 45 - n / 2);  // the Ready countdown, rounded up
  }
  EXPECT_EQ(robot.receive(buf, 0.05), 0u);

  // Return packets: a valid one, one from a team that is not playing, junk.
  UdpSender to_gc("127.0.0.1", link.returnPort());
  ReturnData r;
  r.team_num = 5;
  r.player_num = 3;
  r.fallen = 1;
  to_gc.send(encode(r));
  r.team_num = 99;
  to_gc.send(encode(r));
  const std::array<uint8_t, 7> junk = {'R', 'G', 'r', 't', 4, 1, 2};
  to_gc.send(junk);
  for (int i = 0; i < 100 && link.returnsAccepted() + link.returnsRejected() < 3; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    g.advance(0.01);
    link.update(g);
  }
  EXPECT_EQ(link.returnsAccepted(), 1u);
  EXPECT_EQ(link.returnsRejected(), 2u);
  ASSERT_TRUE(link.lastReturn(5, 3).has_value());
  EXPECT_EQ(link.lastReturn(5, 3)->fallen, 1);
  EXPECT_FALSE(link.lastReturn(99, 3).has_value());
}
