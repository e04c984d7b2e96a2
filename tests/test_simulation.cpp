// The control period pipeline (sim::Simulation): stage order, the one-period
// actuation delay of pipelined mode, and the one check every command goes
// through whatever its source (scripted, in-process agents, a match log).
// Real Bullet, real referee, real match log files.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "simsoccer/match/inprocess_agents.hpp"
#include "simsoccer/sim/log_source.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/run_loop.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

// What happened, in order: "observe 3", "collect 3", "step 4" (a recorder
// sees the tick after the step), "officials", "record 3".
using Trace = std::vector<std::string>;

// Answers every tick for every robot with the stand pose plus `offset(tick)`
// on the head yaw; logs its stages.
class ScriptedSource : public sim::CommandSource {
 public:
  ScriptedSource(const world::World& w, Trace& trace) : world_(w), trace_(trace) {}
  void observe(const sim::Observation& o) override {
    trace_.push_back("observe " + std::to_string(o.tick));
    observed_game_ = o.game != nullptr;
  }
  void collect(uint64_t tick, sim::CommandGate& gate, std::span<sim::CommandSlot> slots) override {
    trace_.push_back("collect " + std::to_string(tick));
    for (world::RobotId r = 0; r < world_.robotCount(); ++r) {
      std::vector<double> position(world::kActuators, 0.0), stiffness(world::kActuators, 1.0);
      position[0] = headYaw(tick);
      if (poison_tick_ == tick) position[3] = std::numeric_limits<double>::quiet_NaN();
      if (auto c =
              gate.check(r, std::span<const double>(position), std::span<const double>(stiffness)))
        slots[r] = {sim::Answer::Given, *c};
    }
  }
  static double headYaw(uint64_t tick) { return 0.001 * static_cast<double>(tick); }
  void poison(uint64_t tick) { poison_tick_ = tick; }
  bool observedGame() const { return observed_game_; }

 private:
  const world::World& world_;
  Trace& trace_;
  uint64_t poison_tick_ = UINT64_MAX;
  bool observed_game_ = false;
};

class TraceRecorder : public sim::Recorder {
 public:
  explicit TraceRecorder(Trace& trace) : trace_(trace) {}
  void record(const sim::PeriodRecord& p) override {
    trace_.push_back("step " + std::to_string(p.world->controlTick()));
    trace_.push_back("record " + std::to_string(p.tick));
  }

 private:
  Trace& trace_;
};

class TraceOfficials : public sim::Officials {
 public:
  explicit TraceOfficials(Trace& trace) : trace_(trace) {}
  void afterStep(std::vector<sim::Event>&) override { trace_.push_back("officials"); }
  referee::ControlData controlData() const override { return {}; }
  int leftTeam() const override { return 0; }

 private:
  Trace& trace_;
};

sim::SimulationConfig modeConfig(sim::Mode mode) {
  sim::SimulationConfig c;
  c.mode = mode;
  return c;
}

// `robots` robots in `mode`, answered by a ScriptedSource, two periods run.
struct ScriptedRun {
  ScriptedRun(int robots, sim::Mode mode)
      : w(test::scenario(robots)), simulation(w, modeConfig(mode)), source(w, trace) {
    simulation.addSource(source);
    simulation.period();
    simulation.period();
  }
  world::World w;
  sim::Simulation simulation;
  Trace trace;
  ScriptedSource source;
};

}  // namespace

TEST(Simulation, SerialStagesRunInOrderAndTheAnswerActsInItsOwnPeriod) {
  world::World w(test::scenario(1));
  sim::Simulation simulation(w, modeConfig(sim::Mode::Serial));
  Trace trace;
  ScriptedSource source(w, trace);
  TraceOfficials officials(trace);
  TraceRecorder recorder(trace);
  simulation.addSource(source);
  simulation.setOfficials(&officials);
  simulation.addRecorder(recorder);
  simulation.period();
  simulation.period();
  const Trace expected = {"observe 0", "collect 0", "officials", "step 1", "record 0",
                          "observe 1", "collect 1", "officials", "step 2", "record 1"};
  EXPECT_EQ(trace, expected);
  EXPECT_TRUE(source.observedGame());  // officials run: sources see the game state
  // The answer to tick 1 was applied in period 1.
  ASSERT_TRUE(simulation.commandApplied(0));
  EXPECT_DOUBLE_EQ(simulation.appliedCommand(0).position[0], ScriptedSource::headYaw(1));
  EXPECT_EQ(simulation.commandStats(0).accepted, 2u);
  EXPECT_EQ(simulation.profile().periods, 2u);
}

TEST(Simulation, PipelinedModeStepsWithTheLastPeriodsAnswers) {
  world::World w(test::scenario(1));
  sim::Simulation simulation(w, modeConfig(sim::Mode::Pipelined));
  Trace trace;
  ScriptedSource source(w, trace);
  TraceRecorder recorder(trace);
  simulation.addSource(source);
  simulation.addRecorder(recorder);
  simulation.period();
  // Period 0 had no answers yet: the world stepped with its initial command.
  EXPECT_FALSE(simulation.commandApplied(0));
  simulation.period();
  simulation.period();
  // Observe, then the step, then the answers to the tick just observed
  // (collected after the step: the drivers computed while it ran).
  const Trace expected = {"observe 0", "collect 0", "step 1", "record 0",
                          "observe 1", "collect 1", "step 2", "record 1",
                          "observe 2", "collect 2", "step 3", "record 2"};
  EXPECT_EQ(trace, expected);
  // Period 2 applied the answer to tick 1: one period of actuation delay.
  ASSERT_TRUE(simulation.commandApplied(0));
  EXPECT_DOUBLE_EQ(simulation.appliedCommand(0).position[0], ScriptedSource::headYaw(1));
  EXPECT_EQ(simulation.commandStats(0).accepted, 2u);
}

// A transport that frees a robot (its driver crashed) drops the answer
// waiting for the next period: the freed robot's hold is not overridden.
TEST(Simulation, APendingAnswerOfAFreedRobotIsNotApplied) {
  ScriptedRun run(1, sim::Mode::Pipelined);
  sim::Simulation& simulation = run.simulation;
  ASSERT_TRUE(simulation.commandApplied(0));
  simulation.dropPending(0);
  simulation.period();
  EXPECT_FALSE(simulation.commandApplied(0));  // the answer to tick 1 was dropped
  simulation.period();
  EXPECT_TRUE(simulation.commandApplied(0));  // the next answers act again
  EXPECT_DOUBLE_EQ(simulation.appliedCommand(0).position[0], ScriptedSource::headYaw(2));
}

// A robot placed or moved after the frame an answer was computed from is no longer where that
// answer was meant for: the answer is not applied (the robot holds what it was placed with), not
// counted as missed, and the answers to frames after the move act again. Serial answers are
// computed after any move and act.
TEST(Simulation, AnAnswerToAFrameFromBeforeTheRobotWasMovedIsNotApplied) {
  for (const sim::Mode mode : {sim::Mode::Pipelined, sim::Mode::Serial}) {
    ScriptedRun run(2, mode);
    world::World& w = run.w;
    sim::Simulation& simulation = run.simulation;
    ASSERT_TRUE(simulation.commandApplied(0));
    const uint64_t placed = w.placements(0);
    w.placeRobot(0, -1.0, 0.5, 0.0);  // as a referee between periods
    EXPECT_EQ(w.placements(0), placed + 1);
    simulation.period();
    EXPECT_EQ(simulation.commandApplied(0), mode == sim::Mode::Serial);
    EXPECT_TRUE(simulation.commandApplied(1));  // the other robot was not moved
    EXPECT_EQ(simulation.commandStats(0).missed, 0u);
    simulation.period();
    EXPECT_TRUE(simulation.commandApplied(0));
    EXPECT_DOUBLE_EQ(simulation.appliedCommand(0).position[0],
                     ScriptedSource::headYaw(mode == sim::Mode::Serial ? 3 : 2));
  }
}

TEST(Simulation, PipelinedModeIsDeterministicAndDiffersFromSerial) {
  // The built-in agents in this process: a striker and a keeper playing.
  const auto run = [](sim::Mode mode) {
    world::Scenario s = test::scenario(2, 5);
    s.robots[1].team = 1;
    s.robots[1].number = 1;
    s.robots[1].x = 2.0;
    s.robots[1].yaw = M_PI;
    s.ball_position = {-1.0, 0.0, -1.0};
    world::World w(s);
    sim::Simulation simulation(w, modeConfig(mode));
    match::InProcessAgents agents(w, {{agents::Role::Striker, agents::Role::Goalkeeper},
                                      5,
                                      true,
                                      test::sourceDir() / "configs" / "agents" / "soccer.yaml",
                                      test::sourceDir() / "configs" / "motions"});
    simulation.addSource(agents);
    sim::RunLoop(simulation, sim::Pacing::Lockstep).run(300);
    // Every in-process command went through the gate: quantised to its resolution.
    for (const double p : simulation.appliedCommand(0).position)
      EXPECT_NEAR(p / world::kCommandResolution, std::round(p / world::kCommandResolution), 1e-6);
    EXPECT_EQ(simulation.commandStats(0).accepted, mode == sim::Mode::Serial ? 300u : 299u);
    return w.stateHash();
  };
  const uint64_t pipelined = run(sim::Mode::Pipelined);
  EXPECT_EQ(pipelined, run(sim::Mode::Pipelined));
  EXPECT_NE(pipelined, run(sim::Mode::Serial));
}

TEST(Simulation, ANaNFromAScriptedSourceIsRefusedAndTheRobotHoldsItsCommand) {
  world::World w(test::scenario(1));
  sim::Simulation simulation(w);
  Trace trace;
  ScriptedSource source(w, trace);
  simulation.addSource(source);
  source.poison(3);
  for (int i = 0; i < 6; ++i) {
    simulation.period();
    if (i == 3) {
      EXPECT_FALSE(simulation.commandApplied(0));
      // Still the answer to tick 2.
      EXPECT_DOUBLE_EQ(simulation.appliedCommand(0).position[0], ScriptedSource::headYaw(2));
    }
  }
  const sim::CommandStats st = simulation.commandStats(0);
  EXPECT_EQ(st.accepted, 5u);
  EXPECT_EQ(st.rejected, 1u);
  EXPECT_EQ(simulation.gate().lastFault(0), sim::CommandFault::NotFinite);
  for (int j = 0; j < static_cast<int>(w.robot(0).model->body->joints.size()); ++j)
    EXPECT_TRUE(std::isfinite(w.jointPosition(0, j)));
}

TEST(Simulation, TheGateNamesWhatIsWrongWithACommand) {
  world::World w(test::scenario(1));
  sim::CommandGate gate(w, 0.5);
  std::vector<float> position(world::kActuators, 0.0f), stiffness(world::kActuators, 0.5f);
  const auto fault = [&] {
    sim::CommandFault f = sim::CommandFault::None;
    gate.check(0, std::span<const float>(position), std::span<const float>(stiffness), &f);
    return f;
  };
  EXPECT_EQ(fault(), sim::CommandFault::None);
  stiffness[4] = 1.5f;
  EXPECT_EQ(fault(), sim::CommandFault::StiffnessRange);
  stiffness[4] = 0.5f;
  position[0] = 40.0f;  // HeadYaw, far beyond its limits
  EXPECT_EQ(fault(), sim::CommandFault::PositionRange);
  position[0] = std::numeric_limits<float>::infinity();
  EXPECT_EQ(fault(), sim::CommandFault::NotFinite);
  position[0] = 0.0f;
  position.pop_back();
  EXPECT_EQ(fault(), sim::CommandFault::WrongSize);
  EXPECT_EQ(gate.rejected(0), 4u);
  EXPECT_STREQ(sim::faultName(sim::CommandFault::NotFinite), "a value is not finite");
}

TEST(Simulation, AReplayedNaNIsRefusedLikeAnyOther) {
  const test::TempDir dir("replay_nan");
  const auto file = dir / "poisoned.log";
  world::World w(test::scenario(1));
  {
    world::MatchLogHeader h;
    h.robots.push_back({0, 1, static_cast<int>(w.robot(0).model->body->joints.size())});
    world::MatchLogWriter log(file, h);
    for (uint64_t tick = 1; tick <= 4; ++tick) {
      std::vector<std::array<double, 25>> position(1), stiffness(1);
      position[0].fill(0.0);
      stiffness[0].fill(1.0);
      if (tick == 2) position[0][7] = std::numeric_limits<double>::quiet_NaN();
      log.write(world::captureFrame(w, tick, position, stiffness, {true}));
    }
  }
  sim::Simulation simulation(w);
  sim::LogSource recorded(file);
  simulation.addSource(recorded);
  int periods = 0;
  while (recorded.next()) {
    simulation.period();
    ++periods;
  }
  EXPECT_EQ(periods, 4);
  EXPECT_EQ(recorded.refused(), 1u);
  EXPECT_EQ(simulation.commandStats(0).rejected, 1u);
  EXPECT_EQ(simulation.commandStats(0).accepted, 3u);
  for (int j = 0; j < static_cast<int>(w.robot(0).model->body->joints.size()); ++j)
    EXPECT_TRUE(std::isfinite(w.jointPosition(0, j)));
}

TEST(Simulation, ModesAreNamedAndABadOneIsRefused) {
  EXPECT_EQ(sim::parseMode("serial"), sim::Mode::Serial);
  EXPECT_EQ(sim::parseMode("pipelined"), sim::Mode::Pipelined);
  try {
    sim::parseMode("parallel");
    FAIL() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("parallel"), std::string::npos);
  }
}

TEST(Simulation, GameOfficialsStartTheGameAndTheirEventsAreReadAfterTheStep) {
  world::World w(test::scenario(2));
  const referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs" / "rules" / "spl.yaml");
  const sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(1, 2);
  sim::GameOfficials officials(w, rules, oc);
  // The operator starts the first half after his pauses: Initial for 1 s,
  // Standby for 1 s (long enough for two 2 Hz GameController packets each), Ready.
  EXPECT_EQ(officials.game().state(), referee::gc::State::Initial);
  sim::Simulation simulation(w);
  simulation.setOfficials(&officials);
  ASSERT_TRUE(simulation.game().has_value());
  EXPECT_EQ(simulation.game()->state, static_cast<uint8_t>(referee::gc::State::Initial));
  EXPECT_FALSE(officials.over());
  // Its events are read after the step, typed.
  struct EventRecorder : sim::Recorder {
    std::vector<std::pair<double, sim::Event>> events;  // with the world time of the period
    void record(const sim::PeriodRecord& p) override {
      for (const sim::Event& e : *p.events) events.emplace_back(p.world->time(), e);
    }
  } recorder;
  simulation.addRecorder(recorder);
  for (int i = 0; i < 250; ++i) simulation.period();  // 2.5 s
  ASSERT_GE(recorder.events.size(), 2u);
  EXPECT_EQ(recorder.events[0].second.type, sim::EventType::State);
  EXPECT_NE(recorder.events[0].second.detail.find("STANDBY"), std::string::npos)
      << recorder.events[0].second.detail;
  EXPECT_NEAR(recorder.events[0].first, 1.0, 0.011);
  EXPECT_NE(recorder.events[1].second.detail.find("READY"), std::string::npos)
      << recorder.events[1].second.detail;
  EXPECT_NEAR(recorder.events[1].first, 2.0, 0.011);
  EXPECT_EQ(simulation.game()->state, static_cast<uint8_t>(referee::gc::State::Ready));
  // Each event once: the start is not reported again.
  EXPECT_EQ(std::count_if(
                recorder.events.begin(), recorder.events.end(),
                [](const auto& e) { return e.second.detail.find("STANDBY") != std::string::npos; }),
            1);
}

// The HSL's GameController has no Standby: the operator goes from Initial to Ready.
TEST(Simulation, UnderHslRulesTheOperatorSkipsStandby) {
  world::World w(test::scenario(2));
  const referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs" / "rules" / "hsl_small_foundation.yaml");
  sim::GameOfficials officials(w, rules, sim::OfficialsConfig::forTeams(1, 2));
  sim::Simulation simulation(w);
  simulation.setOfficials(&officials);
  std::vector<referee::gc::State> states = {officials.game().state()};
  for (int i = 0; i < 150; ++i) {
    simulation.period();
    if (officials.game().state() != states.back()) states.push_back(officials.game().state());
  }
  EXPECT_EQ(states, (std::vector<referee::gc::State>{referee::gc::State::Initial,
                                                     referee::gc::State::Ready}));
  EXPECT_EQ(simulation.game()->competition_type, 0);  // SMALL
  EXPECT_EQ(officials.game().messageBudget(0), 12000);
}

// A drawn game under a rule book with a shoot-out: the operator pauses as GameController3's
// would be seen, so robots get each state: the second half's Finished, the shoot-out's Initial,
// then each kick's Set and Playing and a Finished between kicks (they went from Playing
// straight to the next kick's Set, and from the game's end straight into the shoot-out).
TEST(Simulation, TheOperatorTakesADrawnGameThroughEveryShootoutState) {
  world::World w(test::scenario(4));
  referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs" / "rules" / "spl.yaml");
  rules.half_duration = 2.0;
  rules.half_time_break = 2.0;
  rules.half_time_to_initial = 1.0;
  rules.shootout_shot_duration = 2.0;
  rules.shootout_kicks = 2;
  rules.sudden_death = false;  // (a coin after the kicks)
  sim::GameOfficials officials(w, rules, sim::OfficialsConfig::forTeams(1, 2));
  sim::Simulation simulation(w);
  simulation.setOfficials(&officials);
  using referee::gc::GamePhase;
  using referee::gc::State;
  struct Seen {
    GamePhase phase;
    State state;
    double since;
  };
  std::vector<Seen> seen;
  for (int i = 0; i < 20000 && !officials.over(); ++i) {
    simulation.period();
    const auto& g = officials.game();
    if (seen.empty() || seen.back().phase != g.phase() || seen.back().state != g.state())
      seen.push_back({g.phase(), g.state(), g.time()});
  }
  std::string trace;
  for (const Seen& k : seen)
    trace += std::to_string(static_cast<int>(k.phase)) + "/" +
             std::to_string(static_cast<int>(k.state)) + "@" + std::to_string(k.since) + " ";
  ASSERT_TRUE(officials.over()) << trace;
  const auto at = [&](GamePhase phase, State state, size_t from = 0) {
    for (size_t k = from; k < seen.size(); ++k)
      if (seen[k].phase == phase && seen[k].state == state) return k;
    return seen.size();
  };
  const size_t start = at(GamePhase::PenaltyShoot, State::Initial);
  ASSERT_LT(start, seen.size()) << "no shoot-out";
  ASSERT_GT(start, 0u);
  // Before it: the game's Finished, for the operator's pause.
  EXPECT_EQ(seen[start - 1].phase, GamePhase::Normal);
  EXPECT_EQ(seen[start - 1].state, State::Finished);
  EXPECT_GE(seen[start].since - seen[start - 1].since, 1.0 - 1e-9);
  // Then Initial for the pause, then kicks: Set, Playing, Finished, and Set again after a pause.
  ASSERT_LT(start + 3, seen.size());
  EXPECT_EQ(seen[start + 1].state, State::Set);
  EXPECT_GE(seen[start + 1].since - seen[start].since, 1.0 - 1e-9);
  int kicks = 0;
  for (size_t k = start + 1; k < seen.size(); ++k) {
    EXPECT_EQ(seen[k].phase, GamePhase::PenaltyShoot) << k;
    if (seen[k].state == State::Set) {
      ++kicks;
      EXPECT_EQ(seen[k - 1].state, kicks == 1 ? State::Initial : State::Finished) << k;
      EXPECT_GE(seen[k].since - seen[k - 1].since, 1.0 - 1e-9) << k;
      ASSERT_LT(k + 1, seen.size());
      EXPECT_EQ(seen[k + 1].state, State::Playing) << k;
    }
  }
  EXPECT_EQ(kicks, 4);  // 2 a side, none scores (no agents)
  EXPECT_EQ(seen.back().state, State::Finished);
}

// A followed GameController that hides the kicking side (the Champions Cup: kickingTeam 255 in
// a penalty kick) is asked for its true data as a monitor asks (RGTr to its monitor port), and
// its true data (RGTD, unicast to the listener's port) places the ball on the right mark; the
// robots' packets are not followed while true data comes. Before any true data, the hidden
// side leaves the ball where it is (it went on the -x mark: the wrong one half the time).
TEST(Simulation, AFollowedGameControllerIsAskedForItsTrueData) {
  world::World w(test::scenario(4));
  const referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs" / "rules" / "spl_champions_cup.yaml");
  referee::UdpReceiver monitor_requests(0, "127.0.0.1");
  sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(13, 5);
  oc.external_gc_port = 0;
  oc.external_gc_monitor_port = monitor_requests.port();
  sim::GameOfficials officials(w, rules, oc);
  sim::Simulation simulation(w);
  simulation.setOfficials(&officials);
  referee::UdpSender gc("127.0.0.1", officials.externalGameController()->port());
  referee::ControlData d;
  d.players_per_team = 5;
  d.secs_remaining = 500;
  d.teams[0].team_number = 13;  // team 13 (index 0) defends the left goal
  d.teams[1].team_number = 5;
  for (referee::TeamInfo& t : d.teams)
    for (size_t n = 5; n < t.players.size(); ++n)
      t.players[n].penalty = static_cast<uint8_t>(referee::gc::Penalty::Substitute);
  const auto send = [&](referee::gc::State state, bool true_data, int kicking, int periods) {
    d.state = static_cast<uint8_t>(state);
    d.true_data = true_data;
    d.kicking_team = static_cast<uint8_t>(kicking);
    gc.send(referee::encode(d));
    ++d.packet_number;
    for (int i = 0; i < periods; ++i) simulation.period();
  };
  // The game under way, then a penalty kick as the robots see it: the side hidden.
  d.kicking_team = 13;
  send(referee::gc::State::Ready, false, 13, 10);
  send(referee::gc::State::Set, false, 13, 10);
  send(referee::gc::State::Playing, false, 13, 10);
  test::putBallOnCarpet(w, 0.7, 0.4);
  d.set_play = static_cast<uint8_t>(referee::gc::SetPlay::PenaltyKick);
  send(referee::gc::State::Ready, false, 255, 10);
  send(referee::gc::State::Set, false, 255, 10);
  EXPECT_EQ(officials.game().kickingTeam(), -1);
  EXPECT_NEAR(w.ballState().pose.translation().x(), 0.7, 0.05) << "left where it was";
  // The listener asked for true data: "RGTr" and version 0.
  std::array<uint8_t, 64> request{};
  const size_t n = monitor_requests.receive(request, 2.0);
  ASSERT_EQ(n, 5u);
  EXPECT_EQ(std::string(request.begin(), request.begin() + 4), "RGTr");
  EXPECT_EQ(request[4], 0);
  EXPECT_GE(officials.externalGameController()->monitorRequests(), 1u);
  // The true data: team 5 (right half) takes it, at the left goal's penalty mark.
  send(referee::gc::State::Ready, true, 5, 10);
  send(referee::gc::State::Set, true, 5, 10);
  EXPECT_EQ(officials.game().kickingTeam(), 1);
  const double mark = -(w.field().halfLength() - w.field().penalty_mark_distance.value_or(1.3));
  EXPECT_NEAR(w.ballState().pose.translation().x(), mark, 0.05);
  EXPECT_NEAR(w.ballState().pose.translation().y(), 0.0, 0.05);
  // The robots' copy (hidden side, and Set for 10 s after the whistle) is not followed while
  // true data comes.
  send(referee::gc::State::Playing, true, 5, 5);
  send(referee::gc::State::Set, false, 255, 10);
  EXPECT_EQ(officials.game().state(), referee::gc::State::Playing);
  EXPECT_EQ(officials.game().kickingTeam(), 1);
  EXPECT_GE(officials.externalGameController()->trueData(), 3u);
}

// An external GameController runs the game: packets sent from the test (as
// GameController3 would broadcast them) and the simulated game follows its
// states, scores and penalties; a penalised robot leaves the field and comes
// back; the referee's own calls are only reported.
TEST(Simulation, AnExternalGameControllerRunsTheGame) {
  world::World w(test::scenario(4));
  const referee::RuleBook rules =
      referee::loadRuleBook(test::sourceDir() / "configs" / "rules" / "spl.yaml");
  sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(13, 5);
  oc.external_gc_port = 0;  // any free port
  sim::GameOfficials officials(w, rules, oc);
  sim::Simulation simulation(w);
  simulation.setOfficials(&officials);
  ASSERT_NE(officials.externalGameController(), nullptr);
  referee::UdpSender gc("127.0.0.1", officials.externalGameController()->port());

  referee::ControlData d;  // as GameController3 fills it
  d.players_per_team = 5;
  d.secs_remaining = 600;
  d.teams[0].team_number = 5;  // team 5 (index 1) defends the left goal: the sides follow
  d.teams[1].team_number = 13;
  for (referee::TeamInfo& t : d.teams)
    for (size_t n = 5; n < t.players.size(); ++n)
      t.players[n].penalty = static_cast<uint8_t>(referee::gc::Penalty::Substitute);
  d.kicking_team = 13;
  const auto send = [&](referee::gc::State state, int periods) {
    d.state = static_cast<uint8_t>(state);
    gc.send(referee::encode(d));
    ++d.packet_number;
    for (int i = 0; i < periods; ++i) simulation.period();
  };
  // Nothing happens on its own: no operator, no pauses.
  for (int i = 0; i < 300; ++i) simulation.period();
  EXPECT_EQ(officials.game().state(), referee::gc::State::Initial);
  send(referee::gc::State::Ready, 20);
  EXPECT_EQ(officials.game().state(), referee::gc::State::Ready);
  EXPECT_EQ(officials.game().leftTeam(), 1);
  EXPECT_EQ(officials.game().kickingTeam(), 0);
  send(referee::gc::State::Set, 20);
  send(referee::gc::State::Playing, 20);
  EXPECT_EQ(officials.game().state(), referee::gc::State::Playing);
  // A goal for team 13 and a penalty for team 5's player 2.
  d.teams[1].score = 1;
  d.teams[0].players[1] = {static_cast<uint8_t>(referee::gc::Penalty::RequestForPickup), 45};
  send(referee::gc::State::Playing, 20);
  EXPECT_EQ(officials.game().score(0), 1);
  EXPECT_EQ(officials.game().penalty(1, 2), referee::gc::Penalty::RequestForPickup);
  const world::RobotId penalised = *officials.referee().robot(1, 2);
  EXPECT_GT(std::abs(w.torsoPose(penalised).translation().y()), w.field().halfWidth())
      << "a penalised robot leaves the field";
  d.teams[0].players[1] = {};
  send(referee::gc::State::Playing, 20);
  EXPECT_EQ(officials.game().penalty(1, 2), referee::gc::Penalty::None);
  EXPECT_NEAR(std::abs(w.torsoPose(penalised).translation().y()), w.field().halfWidth(), 0.1)
      << "it comes back on the touchline";
  // The ball goes out: the referee would award a kick-in, but only says so.
  test::putBallOnCarpet(w, 1.0, w.field().halfWidth() + 0.3);
  for (int i = 0; i < 20; ++i) simulation.period();
  EXPECT_EQ(officials.game().currentSetPlay(), referee::gc::SetPlay::None);
  const auto& all = officials.game().events();
  EXPECT_TRUE(std::any_of(all.begin(), all.end(), [](const referee::RefereeEvent& e) {
    return e.type == referee::EventType::Advisory && e.detail.find("set_play") == 0;
  })) << "no advisory kick-in";
  // The game's events: the GameController's states and goal, typed.
  const auto& events = officials.game().events();
  EXPECT_EQ(std::count_if(
                events.begin(), events.end(),
                [](const referee::RefereeEvent& e) { return e.type == referee::EventType::Goal; }),
            1);
  // A packet for another game is not followed; a malformed one is counted.
  referee::ControlData other = d;
  other.teams[0].team_number = 99;
  other.state = static_cast<uint8_t>(referee::gc::State::Finished);
  other.teams[1].score = 7;
  gc.send(referee::encode(other));
  const std::array<uint8_t, 7> junk = {'R', 'G', 'm', 'e', 18, 0, 0};
  gc.send(junk);
  for (int i = 0; i < 20; ++i) simulation.period();
  EXPECT_EQ(officials.game().state(), referee::gc::State::Playing);
  EXPECT_EQ(officials.game().score(0), 1);
  EXPECT_EQ(officials.externalGameController()->rejected(), 1u);
  // Finished in the second half: over once the GameController has said nothing new for 60 s.
  d.first_half = 0;
  send(referee::gc::State::Finished, 100);
  EXPECT_FALSE(officials.over());
  for (int i = 0; i < 5000; ++i) simulation.period();
  EXPECT_FALSE(officials.over());
  for (int i = 0; i < 1000; ++i) simulation.period();
  EXPECT_TRUE(officials.over());
}
