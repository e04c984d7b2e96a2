// The main job end to end: `simsoccer match` with real agent processes over
// DDS, its summary, log, video and heatmap; the same seed twice; replay
// through the physics; an agent killed mid-match; Ctrl-C; the penalty
// scenario; bench scaling. (Label: match, slow.)
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <fstream>
#include <map>
#include <opencv2/videoio.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "simsoccer/engine/config.hpp"
#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/match/match_runner.hpp"
#include "simsoccer/match/match_session.hpp"
#include "simsoccer/sim/simulation.hpp"
#include "simsoccer/world/match_log.hpp"
#include "test_support.hpp"

using namespace simsoccer;

namespace {

const std::string kBin = SIMSOCCER_BIN;

// The value of a top-level "key": number or string in our summary's JSON.
std::string jsonValue(const std::string& json, const std::string& key) {
  const std::regex re("\"" + key + "\": (\"[^\"]*\"|[-0-9.]+|null|true|false|\\[[^\\]]*\\])");
  std::smatch m;
  return std::regex_search(json, m, re) ? m[1].str() : "";
}

// The summary without the lines that hold wall-clock figures.
std::string withoutWallTimes(const std::string& json) {
  std::stringstream in(json), out;
  for (std::string line; std::getline(in, line);)
    if (line.find("wall_seconds") == std::string::npos &&
        line.find("wait_seconds") == std::string::npos &&
        line.find("real_time_factor") == std::string::npos)
      out << line << "\n";
  return out.str();
}

// One short 2 v 2 game (2 x 15 s halves). ctest runs each test in its own
// process, maybe side by side: each plays its own, in its own folder and DDS domain.
struct ShortMatch {
  test::TempDir dir;
  std::string out;
  int status = -1;
};
ShortMatch shortMatch(const std::string& name, int domain, const std::string& extra = "") {
  ShortMatch r{test::TempDir(name), {}, -1};
  r.out =
      test::runCommand(kBin + " match " + (test::sourceDir() / "configs/match_2v2.yaml").string() +
                           " --half 15 --domain " + std::to_string(domain) + " --out " +
                           r.dir.path().string() + " " + extra,
                       r.status);
  return r;
}

// A match of match_2v2.yaml run on a thread while the test acts on it; the
// test's action waits for the game to be under way (the log has grown).
struct BackgroundMatch {
  test::TempDir dir;
  int status = -1;
  std::string out;
  std::thread thread;
  BackgroundMatch(const std::string& name, const std::string& options) : dir(name) {
    thread = std::thread([this, options] {
      out = test::runCommand(kBin + " match " +
                                 (test::sourceDir() / "configs/match_2v2.yaml").string() + " " +
                                 options + " --out " + dir.path().string(),
                             status);
    });
  }
  // True once the log has grown past `bytes` (the game is under way); false
  // after 60 s without.
  bool waitForLog(uintmax_t bytes) const {
    for (int i = 0; i < 600; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      if (std::filesystem::exists(dir / "match.log") &&
          std::filesystem::file_size(dir / "match.log") > bytes)
        return true;
    }
    return false;
  }
  void join() { thread.join(); }
  ~BackgroundMatch() {  // after a failed assertion too: the thread writes into dir
    if (thread.joinable()) thread.join();
  }
};

}  // namespace

TEST(MatchApp, ShortMatchWritesAConsistentSummaryLogVideoAndHeatmap) {
  const ShortMatch m = shortMatch("match_a", 131);
  ASSERT_EQ(m.status, 0) << m.out;
  const std::string summary = test::readFile(m.dir / "summary.json");
  ASSERT_FALSE(summary.empty());
  for (const char* key : {"final_score", "goals", "referee_events", "penalties", "robots",
                          "possession", "agent_restarts", "simulated_seconds", "wall_seconds",
                          "real_time_factor", "seed", "config_hash", "final_state_hash"})
    EXPECT_NE(summary.find(std::string("\"") + key + "\""), std::string::npos) << key;
  EXPECT_EQ(jsonValue(summary, "interrupted"), "false");
  EXPECT_EQ(jsonValue(summary, "aborted"), "null");
  // Per robot: falls, the get-ups among them, and a record per fall whose
  // up_after (s to stand again, or null) is there for each.
  const std::regex robot_re(
      "\"falls\": (\\d+), \"get_ups\": (\\d+), \"keeper_dives\": \\d+, .*\"fall_records\": "
      "\\[(.*)\\]\\}");
  int robots = 0;
  for (std::sregex_iterator it(summary.begin(), summary.end(), robot_re), end; it != end; ++it) {
    ++robots;
    const int falls = std::stoi((*it)[1]), get_ups = std::stoi((*it)[2]);
    const std::string records = (*it)[3];
    EXPECT_LE(get_ups, falls);
    const std::regex up_re("\"up_after\": (null|[0-9.]+)");
    EXPECT_EQ(std::distance(std::sregex_iterator(records.begin(), records.end(), up_re),
                            std::sregex_iterator()),
              falls)
        << records;
  }
  EXPECT_EQ(robots, 4);
  // The game was played: halves and a result.
  EXPECT_NE(summary.find("end of the second half"), std::string::npos);
  EXPECT_NE(summary.find("\"game_over\""), std::string::npos);

  // The log: valid, one frame per control period, its goal events add up to the score.
  world::MatchLogReader log(m.dir / "match.log");
  EXPECT_EQ(log.header().robots.size(), 4u);
  world::LogFrame f;
  int frames = 0, goals[2] = {0, 0};
  double last = 0.0;
  while (log.next(f)) {
    ++frames;
    EXPECT_NEAR(f.time - last, 0.01, 1e-6);
    last = f.time;
    for (const auto& e : f.events)
      if (e.type == "goal" && e.team >= 0 && e.team < 2) ++goals[e.team];
  }
  EXPECT_EQ(std::to_string(frames), jsonValue(summary, "log_frames"));
  EXPECT_NEAR(last, std::stod(jsonValue(summary, "simulated_seconds")), 0.011);
  char score[64];
  std::snprintf(score, sizeof score, "[%d, %d]", goals[0], goals[1]);
  EXPECT_EQ(jsonValue(summary, "final_score"), score);
  // A few MB per minute at most.
  const double mb_per_minute =
      std::filesystem::file_size(m.dir / "match.log") / 1e6 / (last / 60.0);
  EXPECT_LT(mb_per_minute, 5.0);

  // The video: 25 frames per simulated second of the log.
  cv::VideoCapture video((m.dir / "match.mp4").string());
  ASSERT_TRUE(video.isOpened());
  const double expected = std::ceil(last * 25.0 - 1e-6);
  EXPECT_NEAR(video.get(cv::CAP_PROP_FRAME_COUNT), expected, 2.0);
  EXPECT_GT(std::filesystem::file_size(m.dir / "heatmap.png"), 1000u);
}

// Each shipped match plays on its league's field: the SPL's on the SPL field, the HSL Small
// division's on the S-Field with the SPL ball, the Middle division's K1s on the M-Field (the
// Champions Cup 7 v 7 and the HSL Small 7 v 7 shared a scenario, and one field).
TEST(MatchConfig, EachShippedMatchPlaysOnItsLeaguesField) {
  const auto configs = test::sourceDir() / "configs";
  for (const auto& [config, field] : {std::pair{"match_5v5.yaml", "spl.yaml"},
                                      {"match_7v7.yaml", "spl.yaml"},
                                      {"match_2v2.yaml", "spl.yaml"},
                                      {"match_hsl_small_4v4.yaml", "hsl_s_small.yaml"},
                                      {"match_hsl_small_7v7.yaml", "hsl_s_small.yaml"},
                                      {"match_k1_5v5.yaml", "hsl_m.yaml"}}) {
    const match::MatchConfig mc = match::loadMatchConfig(configs / config);
    const match::MatchSession session(mc, 1);
    EXPECT_EQ(session.world().scenario().field_file.filename().string(), field) << config;
  }
}

// A touch of the ball as a spectator counts it: a robot's contact after 0.1 s without one of its
// own, or after another robot's (the world reports the last contact's step after each period).
TEST(MatchSession, BallTouchesAreCountedAsASpectatorCountsThem) {
  match::BallTouchCounter touches(0.005);  // 0.1 s: 20 steps
  auto at = [&](world::RobotId robot, uint64_t step) {
    return touches.next(world::BallTouch{robot, 0, step}).has_value();
  };
  EXPECT_FALSE(touches.next(std::nullopt).has_value());
  EXPECT_TRUE(at(1, 100));   // the first
  EXPECT_FALSE(at(1, 100));  // the same contact, seen again
  EXPECT_FALSE(at(1, 102));  // held on
  EXPECT_FALSE(at(1, 122));  // 20 steps after the last contact: still the same touch
  EXPECT_TRUE(at(1, 143));   // 21 steps after: a new one
  EXPECT_TRUE(at(2, 144));   // another robot's
  EXPECT_TRUE(at(1, 145));   // and back
}

// Who a goal is credited to, as football counts it. A shot going in that a defender touches on
// its way is the shooter's goal, in off that defender (the summary's deflected_by); a ball the
// defender sends into its own goal is an own goal, and so is a shot that goes in more than 2 s
// after the defender's touch. The referee's own rules keep the last touch.
// Real physics and contacts: the attacker touches the ball with its toe, the ball rolls at the
// goal (or lies still), and the defender's toe touches it as it goes in.
TEST(MatchSession, AShotInOffADefenderIsTheShootersGoalAndABallAtRestAnOwnGoal) {
  auto play = [](double speed_before, double seconds_after = 0.0) {
    match::MatchConfig mc = match::loadMatchConfig(test::sourceDir() / "configs/match_2v2.yaml");
    match::MatchSession session(mc, 1);
    sim::Simulation sim(session.world());
    session.attach(sim);
    world::World& w = session.world();
    for (int i = 0; i < 20000 && session.game().state() != referee::gc::State::Playing; ++i)
      sim.period();
    EXPECT_EQ(session.game().state(), referee::gc::State::Playing);
    const int defender = 1;  // its robots are ids 2 and 3; the attacker is team 0's player 2
    const double side = defender == session.game().leftTeam() ? -1.0 : 1.0;
    const double line = side * w.field().halfLength();
    auto toe = [&](world::RobotId r) {
      const int foot = w.robot(r).model->body->linkIndex("LFoot");
      return engine::Vec3(w.linkPose(r, foot) * engine::Vec3(0.12, 0.0075, -0.02));
    };
    auto putBall = [&](const engine::Vec3& at, double vx) {
      engine::RigidBodyState b;
      b.pose = engine::Pose::Identity();
      b.pose.translation() = engine::Vec3(at.x(), at.y(), 0.05);
      b.linear_velocity = engine::Vec3(vx, 0, 0);
      w.setBallState(b);
    };
    // The attacker (team 0's player 2) 2.5 m out, the defender (team 1's player 1) 0.6 m from
    // its line, both facing the goal; team 1's player 2 out of the way.
    w.placeRobot(1, line - side * 2.5, 1.0, side > 0 ? 0.0 : M_PI);
    w.placeRobot(3, line - side * 2.5, -2.0, side > 0 ? 0.0 : M_PI);
    w.placeRobot(2, line - side * 0.6, 0.0, side > 0 ? 0.0 : M_PI);
    putBall(toe(1), 0.0);
    for (int i = 0; i < 5; ++i) sim.period();
    EXPECT_TRUE(w.lastBallTouch() && w.lastBallTouch()->robot == 1u);
    // The ball 1.5 m out, rolling at the goal (or lying still) for a period...
    putBall(engine::Vec3(line - side * 1.5, 0.0, 0.0), side * speed_before);
    sim.period();
    // ...then at the defender's toe, going in at 2 m/s.
    putBall(toe(2), side * 2.0);
    if (seconds_after > 0) {
      // Or stopped after the touch, and rolled in untouched `seconds_after` later.
      sim.period();
      putBall(engine::Vec3(line - side * 0.3, -0.5, 0.0), 0.0);
      const double period = w.scenario().physics.control_period;
      for (int i = 0; i < static_cast<int>(std::lround(seconds_after / period)); ++i) sim.period();
      putBall(engine::Vec3(line - side * 0.3, -0.5, 0.0), side * 1.5);
    }
    for (int i = 0; i < 200 && session.goals().empty(); ++i) sim.period();
    EXPECT_TRUE(w.lastBallTouch() && w.lastBallTouch()->robot == 2u);
    EXPECT_EQ(session.game().score(0), 1);
    // One touch each, counted in the records (the attacker's toe held the ball for 5 periods).
    for (world::RobotId r = 0; r < 4; ++r)
      EXPECT_EQ(session.robots()[r].touches, r == 1 || r == 2 ? 1 : 0) << r;
    return session.goals();
  };
  // Rolling at the goal at 3 m/s before the touch: the shooter's goal, in off player 1. Too slow
  // to reach the line at 0.8 m/s (the SPL ball slows at about 0.45 m/s^2), or at rest: player 1's
  // own goal. Going in, but only 2.5 s after the defender's touch: the defenders had it meanwhile
  // (a save, then their own clearance), so the goal is theirs; 1 s after, still the shot's.
  struct Case {
    double speed_before, seconds_after;
    int scorer;
    bool own_goal;
    int deflected_by;
  };
  for (const Case c :
       {Case{3.0, 0.0, 2, false, 1}, Case{0.8, 0.0, 1, true, 0}, Case{0.0, 0.0, 1, true, 0},
        Case{3.0, 2.5, 1, true, 0}, Case{3.0, 1.0, 2, false, 1}}) {
    const auto goals = play(c.speed_before, c.seconds_after);
    ASSERT_EQ(goals.size(), 1u) << c.speed_before << " " << c.seconds_after;
    EXPECT_EQ(goals[0].team, 0);
    EXPECT_EQ(goals[0].scorer, c.scorer) << c.speed_before << " " << c.seconds_after;
    EXPECT_EQ(goals[0].own_goal, c.own_goal) << c.speed_before << " " << c.seconds_after;
    EXPECT_EQ(goals[0].deflected_by, c.deflected_by) << c.speed_before << " " << c.seconds_after;
  }
}

// A match's agents read the motions and gaits beside its config (a copied configs tree plays its
// own gaits; before, every agent read the ones in its working directory or the source tree), or
// the folder agents.motions names; a folder that is not there is refused, naming the key, and the
// agent refuses a --motions folder that is not there.
TEST(MatchConfig, TheAgentsGetTheMotionsFolderBesideTheMatchConfig) {
  const auto configs = test::sourceDir() / "configs";
  match::MatchConfig mc = match::loadMatchConfig(configs / "match_2v2.yaml");
  EXPECT_TRUE(std::filesystem::equivalent(mc.agent_motions, configs / "motions"))
      << mc.agent_motions;
  mc.half_duration = 15;
  const match::MatchSession session(mc, 1);
  const auto command = match::agentCommand(session, match::RunOptions{}, 0, 1);
  const auto at = std::find(command.begin(), command.end(), "--motions");
  ASSERT_NE(at, command.end());
  ASSERT_NE(at + 1, command.end());
  EXPECT_EQ(*(at + 1), mc.agent_motions.string());
  EXPECT_EQ(std::find(command.begin(), command.end(), "--gone-after"), command.end());
  // Beside a LoLA robot, whose client lockstep may wait for (reconnect_timeout), the agents
  // take the simulator for gone only after that wait and a lockstep timeout more.
  match::MatchConfig with_lola = mc;
  with_lola.lola.robots = match::parseLolaPlayers("2:1");
  const match::MatchSession lola_session(with_lola, 1);
  const auto lola_command = match::agentCommand(lola_session, match::RunOptions{}, 0, 1);
  const auto gone = std::find(lola_command.begin(), lola_command.end(), "--gone-after");
  ASSERT_NE(gone, lola_command.end());
  ASSERT_NE(gone + 1, lola_command.end());
  EXPECT_NEAR(std::stod(*(gone + 1)), 5.0 + with_lola.lola.reconnect_timeout + mc.command_timeout,
              1e-6);

  test::TempDir dir("agent_motions");
  const std::string head =
      "match: motions\nscenario: " + (configs / "scenarios/match_2v2.yaml").string() +
      "\nrules: " + (configs / "rules/spl.yaml").string() + "\n";
  std::ofstream(dir.path() / "named.yaml")
      << head << "agents:\n  motions: " << (configs / "motions").string() << "\n";
  EXPECT_EQ(match::loadMatchConfig(dir.path() / "named.yaml").agent_motions, configs / "motions");
  // The match's Naos would read the K1's keyframes there, and every agent would stop.
  std::ofstream(dir.path() / "k1.yaml")
      << head << "agents:\n  motions: " << (configs / "motions/booster_k1").string() << "\n";
  EXPECT_THROW(match::loadMatchConfig(dir.path() / "k1.yaml"), engine::ConfigError);
  std::ofstream(dir.path() / "none.yaml") << head;  // no motions folder beside it
  EXPECT_TRUE(match::loadMatchConfig(dir.path() / "none.yaml").agent_motions.empty());
  std::ofstream(dir.path() / "bad.yaml") << head << "agents:\n  motions: nowhere\n";
  try {
    match::loadMatchConfig(dir.path() / "bad.yaml");
    FAIL() << "a motions folder that is not there was accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "agents.motions") << e.what();
  }
  int status = 0;
  const std::string out =
      test::runCommand(std::string(SIMSOCCER_AGENT_BIN) + " --team 0 --player 1 --motions " +
                           (dir.path() / "nowhere").string() + " 2>&1",
                       status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("--motions: no such folder"), std::string::npos) << out;
}

// What the agents would stop on is refused when the match config loads, naming the file and
// key: before, the match started, every agent exited on its start-up, and the simulator waited
// 60 s for claims (a penalty run counted each kick a timeout).
TEST(MatchConfig, RefusesWhatTheAgentsOrTheRefereeWouldStopOn) {
  const auto configs = test::sourceDir() / "configs";
  test::TempDir dir("match_refusals");
  std::filesystem::create_directories(dir / "agents");
  {
    std::ifstream in(configs / "agents/soccer.yaml");
    std::ofstream out(dir / "agents/slow.yaml");
    for (std::string line; std::getline(in, line);)
      out << (line.rfind("max_forward:", 0) == 0 ? "max_forward: -0.25" : line) << "\n";
  }
  const std::string head =
      "match: refusals\nscenario: " + (configs / "scenarios/match_2v2.yaml").string() +
      "\nrules: " + (configs / "rules/spl.yaml").string() + "\n";
  const auto refused = [&](const std::string& body, const std::string& file,
                           const std::string& key) {
    std::ofstream(dir / "m.yaml") << head << body;
    try {
      match::loadMatchConfig(dir / "m.yaml");
      ADD_FAILURE() << body << ": accepted";
    } catch (const engine::ConfigError& e) {
      EXPECT_NE(e.file().find(file), std::string::npos) << body << ": " << e.what();
      EXPECT_EQ(e.key(), key) << body << ": " << e.what();
    }
  };
  refused("agents: {role: goalie_king}\n", "m.yaml", "agents.role");
  refused("agents: {config: agents/slow.yaml}\n", "slow.yaml", "max_forward");
  refused("seed: -7\n", "m.yaml", "seed");
  refused("set_duration: -1\n", "m.yaml", "set_duration");
  refused("video: {position: [1, 2, 3], look_at: [1, 2, 3]}\n", "m.yaml", "video.look_at");
  refused("video: {horizontal_fov: 4}\n", "m.yaml", "video.horizontal_fov");
  refused("kicks: 3\n", "m.yaml", "kicks");  // a penalty config's, read by nobody in a match
  std::ofstream(dir / "five.yaml")
      << "match: five\nscenario: " << (configs / "scenarios/match_7v7.yaml").string()
      << "\nrules: " << (configs / "rules/spl.yaml").string() << "\n";
  try {
    match::loadMatchConfig(dir / "five.yaml");
    ADD_FAILURE() << "seven robots a team under a rule book of five: accepted";
  } catch (const engine::ConfigError& e) {
    EXPECT_EQ(e.key(), "players_per_team") << e.what();
  }
  EXPECT_NO_THROW(match::loadMatchConfig(configs / "match_7v7.yaml"));
}

// An agent that exits before it claims its robot (a bad file, a bad option) stops the match at
// once with its status; restarting it would fail the same way. A stand-in agent program beside
// a copy of simsoccer exits 2 at once.
TEST(MatchApp, AnAgentThatExitsOnItsStartUpStopsTheMatchAtOnce) {
  const test::TempDir dir("match_agent_exits");
  std::filesystem::copy_file(kBin, dir / "simsoccer");
  {
    std::ofstream agent(dir / "simsoccer-agent");
    agent << "#!/bin/sh\necho 'simsoccer-agent: config error: made up' >&2\nexit 2\n";
  }
  std::filesystem::permissions(dir / "simsoccer-agent", std::filesystem::perms::owner_all);
  int status = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const std::string out =
      test::runCommand((dir / "simsoccer").string() + " match " +
                           (test::sourceDir() / "configs/match_2v2.yaml").string() +
                           " --half 5 --no-video --out " + (dir / "run").string(),
                       status);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(WEXITSTATUS(status), 1) << out;
  EXPECT_NE(out.find("simsoccer-agent: config error: made up"), std::string::npos) << out;
  EXPECT_NE(out.find("exited (status 2) before it claimed its robot"), std::string::npos) << out;
  EXPECT_LT(seconds, 30.0) << "waited for claims that could not come";
  // No game was played: no log's header is left to look like an earlier run.
  EXPECT_FALSE(std::filesystem::exists(dir / "run" / "match.log"));
}

TEST(MatchApp, SameSeedTwiceGivesTheSameSummaryAndFinalStateHash) {
  // Same config, seed and agent programs => same game, as long as every agent
  // answers every period: a 5 s lockstep timeout (a miss keeps the robot's
  // last command). Each summary counts the misses; both must be 0.
  // (With 0 misses the games still differed under load until the agents
  // waited for the referee's GameState before claiming their robots.)
  const ShortMatch a = shortMatch("match_b1", 132, "--no-video --lockstep-timeout 5");
  ASSERT_EQ(a.status, 0) << a.out;
  const ShortMatch b = shortMatch("match_b2", 137, "--no-video --lockstep-timeout 5");
  ASSERT_EQ(b.status, 0) << b.out;
  const auto& dir = b.dir;
  const std::string one = test::readFile(a.dir / "summary.json"),
                    two = test::readFile(dir / "summary.json");
  for (const std::string* s : {&one, &two}) {
    const std::regex missed("\"missed_commands\": ([0-9]+)");
    int robots = 0;
    for (auto m = std::sregex_iterator(s->begin(), s->end(), missed); m != std::sregex_iterator();
         ++m, ++robots)
      EXPECT_EQ((*m)[1].str(), "0") << "an agent missed lockstep periods: the games may differ";
    EXPECT_EQ(robots, 4);
  }
  EXPECT_EQ(jsonValue(one, "final_state_hash"), jsonValue(two, "final_state_hash"));
  EXPECT_EQ(withoutWallTimes(one), withoutWallTimes(two));
}

// Two runs side by side, neither given a domain: each claims a free one on
// this host (net/domain_claim.hpp), so neither's agents hear the other's
// frames, and both play the game one plays alone. (On one domain a second
// game of match_k1_5v5.yaml seed 1 missed 3 commands and went elsewhere.)
TEST(MatchApp, TwoRunsSideBySideWithoutADomainEachFindTheirOwn) {
  test::TempDir a_dir("match_side_a"), b_dir("match_side_b");
  std::string a_out, b_out;
  int a_status = -1, b_status = -1;
  const auto run = [](const test::TempDir& dir, std::string& out, int& status) {
    out = test::runCommand(
        kBin + " match " + (test::sourceDir() / "configs/match_2v2.yaml").string() +
            " --half 15 --no-video --lockstep-timeout 5 --out " + dir.path().string(),
        status);
  };
  std::thread a([&] { run(a_dir, a_out, a_status); });
  run(b_dir, b_out, b_status);
  a.join();
  ASSERT_EQ(a_status, 0) << a_out;
  ASSERT_EQ(b_status, 0) << b_out;
  const std::regex domain_re("DDS domain ([0-9]+),");
  std::smatch da, db;
  ASSERT_TRUE(std::regex_search(a_out, da, domain_re)) << a_out;
  ASSERT_TRUE(std::regex_search(b_out, db, domain_re)) << b_out;
  EXPECT_NE(da[1].str(), db[1].str());
  const std::string one = test::readFile(a_dir / "summary.json"),
                    two = test::readFile(b_dir / "summary.json");
  for (const std::string* s : {&one, &two}) {
    const std::regex missed("\"missed_commands\": ([0-9]+)");
    for (auto m = std::sregex_iterator(s->begin(), s->end(), missed); m != std::sregex_iterator();
         ++m)
      EXPECT_EQ((*m)[1].str(), "0") << "an agent missed lockstep periods";
  }
  EXPECT_EQ(jsonValue(one, "final_state_hash"), jsonValue(two, "final_state_hash"));
}

TEST(MatchApp, ReplayThroughThePhysicsReproducesEveryStateHash) {
  const ShortMatch m = shortMatch("match_c", 138, "--no-video");
  ASSERT_EQ(m.status, 0) << m.out;
  int status = -1;
  // With one solver thread (Bullet's own loop) and with three: the same game,
  // whatever the number the match ran with; the first also renders a still.
  const auto still = m.dir / "still.png";
  for (const std::string threads : {"1", "3"}) {
    const std::string out = test::runCommand(
        kBin + " replay " + (m.dir / "match.log").string() + " --physics --threads " + threads +
            (threads == "1" ? " --video " + still.string() + " --from 20" : ""),
        status);
    ASSERT_EQ(status, 0) << out;
    EXPECT_NE(out.find("every state hash equal"), std::string::npos) << out;
  }
  EXPECT_TRUE(std::filesystem::exists(still));
  // The re-run's ball touches: at least one, each by a robot of the game, in time order, as many
  // as the summary's robots have (the records count them alike).
  const std::string touches = test::runCommand(
      kBin + " replay " + (m.dir / "match.log").string() + " --physics --touches", status);
  ASSERT_EQ(status, 0) << touches;
  const std::regex touch_line(R"(\s+([0-9.]+) s  touch  team ([01]) player ([12])  (\w+))");
  int count = 0;
  double last = 0;
  for (std::sregex_iterator i(touches.begin(), touches.end(), touch_line), end; i != end; ++i) {
    const double at = std::stod((*i)[1].str());
    EXPECT_GE(at, last) << touches;
    last = at;
    ++count;
  }
  EXPECT_GE(count, 1) << touches;
  std::ifstream summary_file(m.dir / "summary.json");
  const std::string summary((std::istreambuf_iterator<char>(summary_file)),
                            std::istreambuf_iterator<char>());
  const std::regex touches_field(R"("ball_touches": ([0-9]+))");
  int in_summary = 0, robots = 0;
  for (std::sregex_iterator i(summary.begin(), summary.end(), touches_field), end; i != end; ++i) {
    in_summary += std::stoi((*i)[1].str());
    ++robots;
  }
  EXPECT_EQ(robots, 4);
  EXPECT_EQ(in_summary, count) << touches;
  // A part of the log as a video: 2 s at 25 fps.
  const auto part = m.dir / "part.mp4";
  test::runCommand(kBin + " replay " + (m.dir / "match.log").string() + " --video " +
                       part.string() + " --from 10 --to 12",
                   status);
  ASSERT_EQ(status, 0);
  cv::VideoCapture video(part.string());
  EXPECT_NEAR(video.get(cv::CAP_PROP_FRAME_COUNT), 50.0, 1.0);
}

TEST(MatchApp, AKilledAgentIsRestartedAndTheMatchCompletes) {
  BackgroundMatch m("match_kill", "--half 10 --no-video --domain 133");
  EXPECT_TRUE(m.waitForLog(200000)) << "the game did not start";  // kill team 1's player 2
  int kill_status = 0;
  test::runCommand("pkill -f '^[^ ]*simsoccer-agent --team 1 --player 2 --domain 133 '",
                   kill_status);
  m.join();
  const auto& dir = m.dir;
  ASSERT_EQ(m.status, 0) << m.out;
  const std::string summary = test::readFile(dir / "summary.json");
  EXPECT_NE(jsonValue(summary, "agent_restarts"), "[]") << summary;
  EXPECT_NE(summary.find("\"team\": 1, \"player\": 2, \"exit_status\""), std::string::npos);
  EXPECT_NE(summary.find("end of the second half"), std::string::npos);
}

// Agents killed ten times and one stopped for 10 s: the match finishes,
// every restart is in the summary, and no period waits longer than the
// lockstep timeout (a killed agent's robot is released in the next period).
TEST(MatchApp, KilledAndStoppedAgentsNeverStallTheMatch) {
  BackgroundMatch m("match_soak", "--half 20 --no-video --domain 147");
  ASSERT_TRUE(m.waitForLog(100000)) << "the game did not start";
  const auto pidOf = [](int team, int player) {
    int status = 0;
    const std::string out =
        test::runCommand("pgrep -f '^[^ ]*simsoccer-agent --team " + std::to_string(team) +
                             " --player " + std::to_string(player) + " --domain 147 '",
                         status);
    return status == 0 ? std::atoi(out.c_str()) : 0;
  };
  // Ten kills, round robin over the four agents (at most 3 each: the restart limit).
  for (int k = 0; k < 10; ++k) {
    const int team = k % 2, player = 1 + (k / 2) % 2;
    bool killed = false;
    for (int tries = 0; tries < 50 && !killed; ++tries) {  // its restart may not be up yet
      if (const int pid = pidOf(team, player); pid > 0)
        killed = ::kill(pid, SIGKILL) == 0;
      else
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
    EXPECT_TRUE(killed) << "kill " << k << ": no agent " << team << ":" << player;
    std::this_thread::sleep_for(std::chrono::milliseconds(700));
  }
  // One agent stopped for 10 s of wall time, then continued (one killed only
  // twice: after 10 s without a frame it may take the simulator for gone and
  // exit, which is a third restart).
  const int stopped = pidOf(1, 2);
  EXPECT_GT(stopped, 0) << "no agent 1:2 to stop";
  if (const int pid = stopped; pid > 0) {
    ::kill(pid, SIGSTOP);
    std::this_thread::sleep_for(std::chrono::seconds(10));
    ::kill(pid, SIGCONT);
  }
  m.join();
  ASSERT_EQ(m.status, 0) << m.out;
  const std::string summary = test::readFile(m.dir / "summary.json");
  EXPECT_EQ(jsonValue(summary, "aborted"), "null") << summary;
  size_t restarts = 0;
  for (size_t at = summary.find("\"restart\": "); at != std::string::npos;
       at = summary.find("\"restart\": ", at + 1))
    ++restarts;
  EXPECT_GE(restarts, 10u) << summary;
  EXPECT_LE(restarts, 11u) << summary;
  EXPECT_NE(summary.find("end of the second half"), std::string::npos);
  // The timeout, and a margin for a loaded machine's scheduling.
  EXPECT_LE(std::stod(jsonValue(summary, "longest_wait_seconds")), 0.5 + 0.25) << summary;
}

// `simsoccer soak`: two short games, eight agents killed in each (of four agents, at most three
// times each: the restart limit) and one stopped. Each kill is counted once, when its agent is
// gone (a killed agent not yet reaped is never counted again), every one is restarted, and
// each game's summary holds the restarts the table reports.
TEST(SoakApp, EveryKillIsCountedOnceAndEveryKilledAgentIsRestarted) {
  const test::TempDir dir("soak_kills");
  int status = -1;
  const std::string out = test::runCommand(
      kBin + " soak " + (test::sourceDir() / "configs/match_2v2.yaml").string() +
          " --games 2 --half 10 --kills 8 --stops 1 --stop-seconds 0.5 --domain 156 --out " +
          (dir / "soak").string() + " --csv " + (dir / "soak.csv").string() + " 2>&1",
      status);
  // The soak's own checks that concern the agents (its memory check is judged over longer soaks).
  EXPECT_EQ(out.find("did not finish"), std::string::npos) << out;
  EXPECT_EQ(out.find("kills but"), std::string::npos) << out;
  EXPECT_EQ(out.find("kills of the"), std::string::npos) << out;
  EXPECT_EQ(out.find("incomplete"), std::string::npos) << out;
  std::stringstream csv(test::readFile(dir / "soak.csv"));
  std::string line;
  ASSERT_TRUE(std::getline(csv, line)) << out;
  const auto cells = [](const std::string& row) {
    std::vector<std::string> c;
    std::stringstream in(row);
    for (std::string cell; std::getline(in, cell, ',');) c.push_back(cell);
    return c;
  };
  const std::vector<std::string> header = cells(line);
  const auto column = [&](const std::vector<std::string>& row, const std::string& name) {
    for (size_t i = 0; i < header.size() && i < row.size(); ++i)
      if (header[i] == name) return row[i];
    ADD_FAILURE() << "no column " << name << " in " << line;
    return std::string();
  };
  int games = 0;
  while (std::getline(csv, line)) {
    const std::vector<std::string> row = cells(line);
    ++games;
    SCOPED_TRACE("game " + column(row, "game"));
    EXPECT_EQ(column(row, "kills"), "8");
    EXPECT_EQ(column(row, "stops"), "1");
    EXPECT_EQ(column(row, "finished"), "yes");
    EXPECT_EQ(column(row, "summary_complete"), "yes");
    const int restarts = std::atoi(column(row, "restarts").c_str());
    EXPECT_GE(restarts, 8);
    const std::string summary =
        test::readFile(dir / "soak" / ("game_" + column(row, "game")) / "summary.json");
    int told = 0;
    for (size_t at = summary.find("\"restart\": "); at != std::string::npos;
         at = summary.find("\"restart\": ", at + 1))
      ++told;
    EXPECT_EQ(told, restarts) << summary;
  }
  EXPECT_EQ(games, 2) << out;
}

TEST(MatchApp, CtrlCLeavesAValidTruncatedLogAndSummary) {
  BackgroundMatch m("match_int", "--no-video --domain 134");
  EXPECT_TRUE(m.waitForLog(100000)) << "the game did not start";
  int s = 0;
  test::runCommand("pkill -INT -f '^" + kBin + " match .*--domain 134 '", s);
  m.join();
  const auto& dir = m.dir;
  EXPECT_EQ(WEXITSTATUS(m.status), 130) << m.out;
  const std::string summary = test::readFile(dir / "summary.json");
  EXPECT_EQ(jsonValue(summary, "interrupted"), "true") << summary;
  world::MatchLogReader log(dir / "match.log");
  world::LogFrame f;
  int frames = 0;
  while (log.next(f)) ++frames;
  EXPECT_GT(frames, 100);
  EXPECT_EQ(std::to_string(frames), jsonValue(summary, "log_frames"));
  // No agent is left behind.
  int ps = 0;
  const std::string left = test::runCommand("pgrep -f '^[^ ]*simsoccer-agent .*--domain 134 '", ps);
  EXPECT_TRUE(left.empty()) << left;
}

TEST(MatchApp, AKilledSimulatorTakesItsAgentsWithIt) {
  BackgroundMatch m("match_kill9", "--no-video --domain 154");
  EXPECT_TRUE(m.waitForLog(100000)) << "the game did not start";
  const auto agents = [] {
    int ps = 0;
    return test::runCommand("pgrep -f '^[^ ]*simsoccer-agent .*--domain 154 '", ps);
  };
  ASSERT_FALSE(agents().empty()) << "no agents to be left behind";
  int s = 0;
  test::runCommand("pkill -KILL -f '^" + kBin + " match .*--domain 154 '", s);
  ASSERT_EQ(s, 0) << "no simulator to kill";
  m.join();
  EXPECT_EQ(WEXITSTATUS(m.status), 128 + SIGKILL) << m.out;  // through the shell
  // SIGKILL: the match could not stop its agents; each asked the kernel to
  // be told when its parent dies, and exits at once (not after 5 s without frames).
  const auto t0 = std::chrono::steady_clock::now();
  std::string left = agents();
  while (!left.empty() && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    left = agents();
  }
  EXPECT_TRUE(left.empty()) << "agents left 2 s after the simulator was killed: " << left;
}

TEST(MatchApp, BadConfigAndUnwritableOutputFailBeforeAnythingRuns) {
  const test::TempDir dir("match_bad");
  std::ofstream(dir / "bad.yaml") << "match: bad\nscenario: nowhere.yaml\nrules: rules/spl.yaml\n";
  int status = 0;
  std::string out = test::runCommand(kBin + " match " + (dir / "bad.yaml").string(), status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("bad.yaml"), std::string::npos) << out;
  EXPECT_NE(out.find("scenario"), std::string::npos) << out;
  out =
      test::runCommand(kBin + " match " + (test::sourceDir() / "configs/match_2v2.yaml").string() +
                           " --out /proc/simsoccer_no",
                       status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("/proc/simsoccer_no"), std::string::npos) << out;
  // Bad options: refused with `message`, before anything is written.
  const auto refused = [&](const std::string& options, const std::string& message) {
    const std::string said = test::runCommand(
        kBin + " match " + (test::sourceDir() / "configs/match_2v2.yaml").string() + " " + options +
            " --out " + (dir / "never").string(),
        status);
    EXPECT_NE(status, 0);
    EXPECT_NE(said.find(message), std::string::npos) << said;
    EXPECT_FALSE(std::filesystem::exists(dir / "never"));
  };
  refused("--lockstep-timeout 0", "--lockstep-timeout must be > 0");
  // A folder that holds an earlier run is not written over unless asked.
  std::filesystem::create_directories(dir / "earlier");
  std::ofstream(dir / "earlier" / "summary.json") << "{}\n";
  const std::string kept =
      test::runCommand(kBin + " match " + (test::sourceDir() / "configs/match_2v2.yaml").string() +
                           " --out " + (dir / "earlier").string(),
                       status);
  EXPECT_NE(status, 0);
  EXPECT_NE(kept.find("holds an earlier run (summary.json): give another --out, or --overwrite"),
            std::string::npos)
      << kept;
  EXPECT_EQ(test::readFile(dir / "earlier" / "summary.json"), "{}\n");
  EXPECT_FALSE(std::filesystem::exists(dir / "earlier" / "match.log"));
  refused("--dds-config /nonexistent/lan.xml", "--dds-config /nonexistent/lan.xml: no such file");
}

// --dds-config: the simulator and the agents it starts use configs/dds/lan.xml
// (discovery by multicast on a network interface): 2 s of a game, every
// period answered.
TEST(MatchApp, RunsOverTheLanDdsConfiguration) {
  const auto interface_address = test::multicastInterfaceAddress();
  if (!interface_address) GTEST_SKIP() << "no network interface that can multicast";
  const test::TempDir dir("match_lan");
  test::SpdpMulticastListener announcements(139, *interface_address);
  ASSERT_TRUE(announcements.ok());
  int status = -1;
  const std::string out = test::runCommand(
      kBin + " match " + (test::sourceDir() / "configs/match_2v2.yaml").string() +
          " --max-seconds 2 --no-video --lockstep-timeout 5 --domain 139 --dds-config " +
          (test::sourceDir() / "configs/dds/lan.xml").string() + " --out " + dir.path().string(),
      status);
  ASSERT_EQ(status, 0) << out;
  const std::string summary = test::readFile(dir / "summary.json");
  const std::regex missed("\"missed_commands\": ([0-9]+)");
  int robots = 0;
  for (auto m = std::sregex_iterator(summary.begin(), summary.end(), missed);
       m != std::sregex_iterator(); ++m, ++robots)
    EXPECT_EQ((*m)[1].str(), "0");
  EXPECT_EQ(robots, 4) << summary;
  // The simulator and its 4 agents announced themselves by multicast on the
  // network interface.
  EXPECT_GE(announcements.received(), 5);
}

TEST(PenaltyApp, FiveKicksGiveOutcomesAndARate) {
  const test::TempDir dir("penalty");
  int status = -1;
  const std::string out =
      test::runCommand(kBin + " penalty " + (test::sourceDir() / "configs/penalty.yaml").string() +
                           " --kicks 5 --video-kicks 1 --domain 135 --out " + dir.path().string(),
                       status);
  ASSERT_EQ(status, 0) << out;
  const std::string json = test::readFile(dir / "penalty.json");
  EXPECT_EQ(jsonValue(json, "kicks"), "5");
  const std::regex outcome("\"(goal|saved|missed|timeout)\"");
  const std::string list = json.substr(json.find("\"outcomes\""));
  int kicks = 0, goals = 0;
  for (auto it = std::sregex_iterator(list.begin(), list.end(), outcome);
       it != std::sregex_iterator(); ++it) {
    ++kicks;
    goals += (*it)[1] == "goal";
  }
  EXPECT_EQ(kicks, 5);
  // The rate is the outcomes' goals, and its interval holds it.
  const double rate = std::stod(jsonValue(json, "scoring_rate"));
  EXPECT_NEAR(rate, goals / 5.0, 1e-3);
  const std::string ci = jsonValue(json, "ci95");
  double lo = -1, hi = -1;
  ASSERT_EQ(std::sscanf(ci.c_str(), "[%lf, %lf]", &lo, &hi), 2) << ci;
  EXPECT_LE(lo, rate);
  EXPECT_GE(hi, rate);
  EXPECT_LT(lo, hi);
  // Wilson's interval for `goals` of 5 (z = 1.96), to the printed precision.
  const double z = 1.96, n = 5.0, denom = 1 + z * z / n;
  const double centre = (rate + z * z / (2 * n)) / denom;
  const double half = z * std::sqrt(rate * (1 - rate) / n + z * z / (4 * n * n)) / denom;
  EXPECT_NEAR(lo, std::max(0.0, centre - half), 0.006) << ci;
  EXPECT_NEAR(hi, std::min(1.0, centre + half), 0.006) << ci;
  EXPECT_NE(out.find("95% CI"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "kick_1.mp4"));
}

TEST(BenchScalingApp, OneAndTwoRobotsWriteCsvAndPlot) {
  const test::TempDir dir("scaling");
  int status = -1;
  const std::string out = test::runCommand(
      kBin + " bench scaling --robots 1,2 --seconds 2 --domain 136 --csv " +
          (dir / "scaling.csv").string() + " --png " + (dir / "scaling.png").string(),
      status);
  ASSERT_EQ(status, 0) << out;
  const auto lines = test::readLines(dir / "scaling.csv");
  // Both period modes per robot count (the default --modes serial,pipelined).
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].rfind("robots,mode,steps_per_s,fps,rtf", 0), 0u) << lines[0];
  EXPECT_EQ(lines[1].rfind("1,serial,", 0), 0u) << lines[1];
  EXPECT_EQ(lines[2].rfind("1,pipelined,", 0), 0u) << lines[2];
  EXPECT_EQ(lines[3].rfind("2,serial,", 0), 0u) << lines[3];
  EXPECT_EQ(lines[4].rfind("2,pipelined,", 0), 0u) << lines[4];
  // Every agent answered every period in both modes (the column `missed`).
  for (size_t i = 1; i < lines.size(); ++i) {
    const auto cells = test::splitCsv(lines[i]);
    const auto header = test::splitCsv(lines[0]);
    const auto missed = std::find(header.begin(), header.end(), "missed") - header.begin();
    ASSERT_LT(static_cast<size_t>(missed), cells.size()) << lines[i];
    EXPECT_EQ(cells[static_cast<size_t>(missed)], "0") << lines[i];
  }
  EXPECT_GT(std::filesystem::file_size(dir / "scaling.png"), 1000u);
}

// Booster K1s (--robot booster_k1): their agent processes get the K1's model, gait, motions
// and agent config, and answer every period.
TEST(BenchScalingApp, BoosterK1AgentsOnTheMField) {
  const test::TempDir dir("scaling_k1");
  int status = -1;
  const std::string out = test::runCommand(
      kBin +
          " bench scaling --robot booster_k1 --robots 2 --seconds 3 --modes serial --domain 143 "
          "--csv " +
          (dir / "scaling.csv").string() + " --png " + (dir / "scaling.png").string(),
      status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("booster_k1"), std::string::npos) << out;
  const auto lines = test::readLines(dir / "scaling.csv");
  ASSERT_EQ(lines.size(), 2u);
  const auto header = test::splitCsv(lines[0]), cells = test::splitCsv(lines[1]);
  const auto missed = std::find(header.begin(), header.end(), "missed") - header.begin();
  ASSERT_LT(static_cast<size_t>(missed), cells.size());
  EXPECT_EQ(cells[static_cast<size_t>(missed)], "0") << lines[1];
  EXPECT_NE(test::runCommand(kBin + " bench scaling --robot nao_h99 2>&1", status).find("nao_h99"),
            std::string::npos);
  EXPECT_NE(status, 0);
}

// `serve` given a match config, with the agents the match would start (the
// match library's command lines), plays the same game as `match`: the same
// config and seed give the same final state hash, and twice the same.
TEST(ServeApp, PlaysTheSameGameAsMatchWithTheSameAgents) {
  const std::string config = (test::sourceDir() / "configs/match_2v2.yaml").string();
  const uint64_t seed = 5;
  const ShortMatch m = shortMatch("serve_vs_match", 140, "--seed 5 --max-seconds 4 --no-video");
  ASSERT_EQ(m.status, 0) << m.out;
  const std::string summary = test::readFile(m.dir / "summary.json");
  const std::string match_hash = jsonValue(summary, "final_state_hash");
  ASSERT_EQ(match_hash.size(), 18u) << summary;  // "%016x" in quotes
  EXPECT_EQ(jsonValue(summary, "simulated_seconds"), "4.00");
  for (int run = 0; run < 2; ++run) {
    match::MatchConfig mc = match::loadMatchConfig(config);
    mc.half_duration = 15;  // as shortMatch plays it
    const match::MatchSession session(mc, seed);
    match::RunOptions o;
    o.seed = seed;
    o.domain = 141;
    o.dds_config = test::sourceDir() / "configs/dds/loopback.xml";
    std::vector<std::unique_ptr<match::ChildProcess>> agents;
    for (world::RobotId r = 0; r < session.world().robotCount(); ++r) {
      auto command = match::agentCommand(session, o, session.world().robot(r).team,
                                         session.world().robot(r).number);
      command[0] = SIMSOCCER_AGENT_BIN;  // beside the programs, not this test
      agents.push_back(std::make_unique<match::ChildProcess>(command));
    }
    int status = -1;
    const std::string out = test::runCommand(
        kBin + " serve " + config + " --half 15 --seed 5 --seconds 4 --domain 141 2>&1", status);
    ASSERT_EQ(status, 0) << out;
    std::smatch hash;
    ASSERT_TRUE(std::regex_search(out, hash, std::regex("final state hash ([0-9a-f]{16})"))) << out;
    EXPECT_EQ("\"" + hash[1].str() + "\"", match_hash) << "serve run " << run + 1 << ":\n" << out;
    // Every robot answered every period (a miss would change the game).
    const std::regex missed("missed ([0-9]+)");
    int robots = 0;
    for (auto it = std::sregex_iterator(out.begin(), out.end(), missed);
         it != std::sregex_iterator(); ++it, ++robots)
      EXPECT_EQ((*it)[1].str(), "0") << out;
    EXPECT_EQ(robots, static_cast<int>(session.world().robotCount())) << out;
    EXPECT_NE(out.find("simulated 4.00 s"), std::string::npos) << out;
  }
}

// The worked example's shape, small: a 2 v 2 whose robot 2:1 a LoLA client
// drives through `simsoccer lola-run` (its socket at /tmp/robocup in a
// private namespace), the others built-in agents over DDS. The robot plays
// the whole game at LoLA's 12 ms cycle, the summary counts the client's maps
// (and its unknown keys), and the log keeps the LED colours it set. The client comes 7 s late
// and no DDS agent is lost waiting for it.
TEST(MatchApp, ALolaRobotPlaysThroughItsSocketBesideDdsAgents) {
  if (!test::bubblewrapWorks()) GTEST_SKIP() << "bubblewrap cannot make a namespace here";
  BackgroundMatch m("match_lola",
                    "--lola 2:1 --half 5 --max-seconds 20 --no-video --quiet --domain 97");
  const auto socket = m.dir / "lola" / "robot_2_1.sock";
  bool up = false;
  for (int i = 0; i < 600 && !up; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    up = std::filesystem::is_socket(socket);
  }
  ASSERT_TRUE(up) << "no LoLA socket at " << socket;
  // A team starts its binary by hand, maybe late: the match waits for it before it starts the
  // DDS agents (after 5 s without a frame an agent would take the simulator for gone and exit).
  std::this_thread::sleep_for(std::chrono::seconds(7));
  match::ChildProcess client({kBin, "lola-run", "--robot", "2:1", "--run", m.dir.path().string(),
                              "--", SIMSOCCER_LOLA_CLIENT, "--mode", "unknown", "--joint",
                              "HeadYaw=0.4"});
  m.join();
  for (int i = 0; i < 500 && client.running(); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_FALSE(client.running());
  EXPECT_EQ(client.exitStatus(), 0) << "the strict client refused a sensor map";
  ASSERT_EQ(m.status, 0) << m.out;
  EXPECT_NE(m.out.find("LoLA robot 2:1 at"), std::string::npos) << m.out;
  const std::string summary = test::readFile(m.dir / "summary.json");
  EXPECT_EQ(jsonValue(summary, "control_period"), "0.012");
  EXPECT_EQ(jsonValue(summary, "agent_restarts"), "[]") << summary;
  const std::regex lola(
      "\"lola\": \\[\\s*\\{\"team\": 2, \"player\": 1, \"socket\": \"[^\"]+\", "
      "\"address\": null, \"sessions\": 1, \"packets_sent\": ([0-9]+), "
      "\"packets_dropped\": 0, \"answered\": ([0-9]+), \"missed\": 0, "
      "\"no_client\": [0-9]+, \"maps\": [0-9]+, \"bad_maps\": 0, "
      "\"unknown_keys\": ([0-9]+)");
  std::smatch match;
  ASSERT_TRUE(std::regex_search(summary, match, lola)) << summary;
  EXPECT_GE(std::stoi(match[1].str()), 1000);  // 20 s at 12 ms, less the wait
  EXPECT_EQ(match[1].str(), match[2].str());   // every map answered
  EXPECT_GT(std::stoi(match[3].str()), 0);
  // The log: the client's blue chest on robot 2:1 (world index 2), none on the others.
  world::MatchLogReader log(m.dir / "match.log");
  world::LogFrame f, last;
  while (log.next(f)) last = f;
  ASSERT_EQ(last.robots.size(), 4u);
  ASSERT_TRUE(last.robots[2].leds.has_value());
  EXPECT_EQ((*last.robots[2].leds)[2], 255);
  EXPECT_FALSE(last.robots[0].leds.has_value());
}
