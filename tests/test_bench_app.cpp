// End to end: the real `simsoccer bench physics` program, its table and CSV.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <utility>

#include "test_support.hpp"

using simsoccer::test::runCommand;
namespace test = simsoccer::test;

TEST(BenchPhysicsApp, PrintsTableAndWritesCsv) {
  const test::BenchRun run =
      test::runBench(SIMSOCCER_BIN, "bench physics --robots 1,2 --seconds 0.5");
  const std::string& out = run.out;
  ASSERT_EQ(run.status, 0) << out;
  EXPECT_NE(out.find("steps_per_s"), std::string::npos);
  EXPECT_NE(out.find("real_time_factor"), std::string::npos);
  const std::vector<std::string>& lines = run.lines;
  ASSERT_GE(lines.size(), 3u);
  const std::string &header = lines[0], &row1 = lines[1], &row2 = lines[2];
  EXPECT_EQ(header.rfind("robots,", 0), 0u) << header;
  EXPECT_EQ(row1.rfind("1,", 0), 0u) << row1;
  EXPECT_EQ(row2.rfind("2,", 0), 0u) << row2;
  EXPECT_FALSE(lines.size() > 3 && !lines[3].empty());  // no further rows
  // Both robots of the pair still stand: "2/2" in the standing column.
  EXPECT_NE(row2.find(",2/2,"), std::string::npos) << row2;
}

// --dt adds rows at other steps; the project's default step (10 ms) is always
// run first, and the summary gives each other step's real-time factor against it.
TEST(BenchPhysicsApp, OtherStepsBesideTheDefaultStep) {
  const test::BenchRun run = test::runBench(
      SIMSOCCER_BIN, "bench physics --robots 1 --seconds 0.2 --dt 0.005 --iterations 5");
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("5 solver iterations"), std::string::npos) << run.out;
  ASSERT_GE(run.lines.size(), 3u);
  EXPECT_EQ(run.lines[0].rfind("robots,dt_ms,steps_per_s,", 0), 0u) << run.lines[0];
  EXPECT_EQ(run.lines[1].rfind("1,10,", 0), 0u) << run.lines[1];
  EXPECT_EQ(run.lines[2].rfind("1,5,", 0), 0u) << run.lines[2];
  EXPECT_NE(run.out.find("1 robots: real-time factor "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(" at the default step (10 ms); "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find(" at 5 ms ("), std::string::npos) << run.out;
}

TEST(BenchPhysicsApp, RejectsBadOptions) {
  int status = -1;
  const std::string out =
      runCommand(std::string(SIMSOCCER_BIN) + " bench physics --robots 0", status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("--robots"), std::string::npos) << out;
  for (const char* bad :
       {"--dt 0", "--dt 0.005,x", "--dt 1", "--iterations 0", "--joint-sweeps 0"}) {
    const std::string refused =
        runCommand(std::string(SIMSOCCER_BIN) + " bench physics " + bad, status);
    EXPECT_NE(status, 0) << bad;
    EXPECT_NE(refused.find(std::string(bad).substr(0, std::string(bad).find(' '))),
              std::string::npos)
        << refused;
  }
  const std::string help = runCommand(std::string(SIMSOCCER_BIN) + " bench physics --help", status);
  EXPECT_EQ(status, 0);
  EXPECT_NE(help.find("--csv"), std::string::npos);
}

TEST(CheckApp, ValidScenarioAndConfigError) {
  int status = -1;
  const std::string ok = runCommand(std::string(SIMSOCCER_BIN) + " check " + SIMSOCCER_SOURCE_DIR +
                                        "/configs/scenarios/lineup_5v5.yaml",
                                    status);
  EXPECT_EQ(status, 0) << ok;
  EXPECT_NE(ok.find("robot 9: team 1 number 5, nao_h21"), std::string::npos) << ok;
  const test::TempDir dir("check");
  const auto bad = dir / "simsoccer_check_bad.yaml";
  std::ofstream(bad) << "scenario: bad\nfield: " << SIMSOCCER_SOURCE_DIR
                     << "/fields/spl.yaml\nrobot_model: " << SIMSOCCER_SOURCE_DIR
                     << "/robots/nao_v6_h25.yaml\nphysics: {dt: 0.005, control_period: 0.012}\n"
                        "seed: 1\n";
  const std::string err = runCommand(std::string(SIMSOCCER_BIN) + " check " + bad.string(), status);
  EXPECT_NE(status, 0);
  EXPECT_NE(err.find("simsoccer_check_bad.yaml: physics.control_period: must be a whole multiple"),
            std::string::npos)
      << err;
}

// Every kind of config file the programs read: a valid one is summarised, one `check` does
// not know is refused naming it.
TEST(CheckApp, EveryKindOfConfigFile) {
  const std::string src = SIMSOCCER_SOURCE_DIR;
  const std::vector<std::pair<std::string, std::string>> kinds = {
      {"/configs/match_k1_5v5.yaml", "match config 'match_k1_5v5' is valid"},
      {"/configs/penalty.yaml", "penalty config 'penalty' is valid"},
      {"/fields/hsl_m.yaml", "field 'hsl_m' is valid"},
      {"/robots/booster_k1.yaml", "robot 'booster_k1' is valid"},
      {"/configs/rules/spl_champions_cup.yaml", "(7 players a team"},
      {"/configs/agents/soccer_k1.yaml", "agent behaviour file is valid"},
      {"/configs/motions/booster_k1/gait.yaml", "gait file is valid"},
      {"/configs/bench/physics_k1.yaml", "benchmark scene is valid"},
      {"/configs/bench/motion_booster_k1.yaml", "motion bench of booster_k1 is valid"}};
  int status = -1;
  for (const auto& [file, said] : kinds) {
    const std::string out = runCommand(std::string(SIMSOCCER_BIN) + " check " + src + file, status);
    EXPECT_EQ(status, 0) << file << ": " << out;
    EXPECT_NE(out.find(said), std::string::npos) << file << ": " << out;
  }
  // A match config's scenario is checked with it: the world is built.
  EXPECT_NE(
      runCommand(std::string(SIMSOCCER_BIN) + " check " + src + "/configs/match_2v2.yaml", status)
          .find("state hash"),
      std::string::npos);
  const std::string motion = runCommand(
      std::string(SIMSOCCER_BIN) + " check " + src + "/configs/motions/sit_down.yaml", status);
  EXPECT_NE(status, 0);
  EXPECT_NE(motion.find("sit_down.yaml: (document): not a file `check` knows"), std::string::npos)
      << motion;
}

// Found by probing the programs as a new user (2026-12-07): each of these ran (a bench to its
// end before failing to write its table), printed nonsense, or blamed the wrong argument.
TEST(CliApp, BadOptionsAreRefusedBeforeAnythingRuns) {
  const std::string bin = SIMSOCCER_BIN, src = SIMSOCCER_SOURCE_DIR;
  const test::TempDir dir("cli_refusals");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"match " + src + "/configs/match_2v2.yaml --seed --half 5", "option --seed needs a value"},
      {"bench physics --csv " + (dir / "none" / "x.csv").string(), "x.csv: no such folder"},
      {"bench physics --csv " + dir.path().string(), ": is a folder"},
      {"bench scaling --png /proc/simsoccer_no/s.png", "no such folder /proc/simsoccer_no"},
      {"bench motion --max-forward -5", "walk.max_forward: must be > 0"},
      {"bench motion --period 0", "walk.step_period: must be > 0"},
      {"bench motion --striker-trials -1", "--striker-trials must be a whole number from 0"},
      {"bench motion --vx 0.2 --seconds 0", "--seconds must be > 0"},
      {"bench motion --dt 0", "--dt must be > 0"},
      {"bench motion --kick --foot 7", "--foot must be a whole number from 0 to 1"},
      {"bench motion --vx 0.2 --motions " + (dir / "none").string(), "--motions: no such folder"},
      {"replay " + dir.path().string(), ": is a folder"},
      {"replay " + (dir / "x.log").string() + " --video out.gif",
       "--video out.gif: .mp4, .avi or .png"},
      {"replay " + (dir / "x.log").string() + " --from -5", "--from must be >= 0"},
      {"replay " + (dir / "x.log").string() + " --touches", "--touches goes with --physics"},
      {"bench physics --robots 1000", "the benchmark's grid holds at most"},
      {"serve " + src + "/configs/scenarios/k1_3v3.yaml --booster-domain 9",
       "--booster-domain, --booster-lockstep and --booster-netns go with --booster"},
      {"serve " + src + "/configs/scenarios/lineup_5v5.yaml --teams 1,1",
       "--teams: two different team numbers 1..254"},
      {"bench", "usage: simsoccer bench physics|sensors|net|cameras|motion|scaling"},
      {"match " + src + "/configs/match_2v2.yaml --lola-net", "--lola-net: no LoLA robots"},
      {"match " + src + "/configs/match_2v2.yaml --external-gc 3939",
       "--external-gc 3939: the GameController's own port"},
      {"serve " + src + "/configs/match_2v2.yaml --teams 3,4",
       "--teams: a match config names its own teams"},
      {"lola-run --socket s --robot 1:1 -- true", "--socket and --robot exclude each other"},
      {"lola-run --robot 1:1 --prefix 10.0 -- true", "--prefix and --bridge go with --net"},
      {"booster-run -- true", "--robot T:P is required"},
      {"booster-run --robot 1:1 --profile " + (dir / "none.xml").string() + " -- true",
       "none.xml: no such file"}};
  for (const auto& [args, message] : cases) {
    int status = -1;
    const std::string out = runCommand(bin + " " + args, status);
    EXPECT_EQ(WEXITSTATUS(status), 2) << args << ": " << out;
    EXPECT_NE(out.find(message), std::string::npos) << args << ": " << out;
  }
  int status = -1;
  // A rule book whose teams are smaller than the scenario's: the others would be substitutes.
  const std::string eleven =
      runCommand(bin + " serve " + src + "/configs/scenarios/match_11v11.yaml --rules " + src +
                     "/configs/rules/spl.yaml",
                 status);
  EXPECT_NE(status, 0);
  EXPECT_NE(eleven.find("spl.yaml: players_per_team: 5, but"), std::string::npos) << eleven;
  // A robot named on the command line is the option's fault, and nothing is written.
  const std::string lola =
      runCommand(bin + " match " + src + "/configs/match_2v2.yaml --lola 2:3 --out " +
                     (dir / "lola_run").string(),
                 status);
  EXPECT_NE(status, 0);
  EXPECT_NE(lola.find("--lola: no robot 2:3 in the match"), std::string::npos) << lola;
  EXPECT_FALSE(std::filesystem::exists(dir / "lola_run"));
  // A match authority is not replaced unless asked: the credentials it signed would stop working.
  std::filesystem::create_directories(dir / "creds");
  std::ofstream(dir / "creds" / "ca.pem") << "kept\n";
  EXPECT_NE(runCommand(bin + " credentials " + (dir / "creds").string(), status)
                .find("holds a match authority (ca.pem)"),
            std::string::npos);
  EXPECT_EQ(test::readFile(dir / "creds" / "ca.pem"), "kept\n");
  EXPECT_NE(runCommand(bin + " bench --help", status).find("simsoccer bench NAME --help"),
            std::string::npos);
  EXPECT_EQ(status, 0);
  // A soccer option without --role is refused by the agent, not ignored.
  const std::string agent = (std::filesystem::path(bin).parent_path() / "simsoccer-agent").string();
  const std::string seed = runCommand(agent + " --team 0 --player 1 --seed 3", status);
  EXPECT_EQ(WEXITSTATUS(status), 2) << seed;
  EXPECT_NE(seed.find("--seed goes with --role"), std::string::npos) << seed;
  // A second YAML document would be read by nobody; a behaviour the agents do not have.
  std::ofstream(dir / "two.yaml") << "field: x\n---\n---\nfield: y\n";
  EXPECT_NE(runCommand(bin + " check " + (dir / "two.yaml").string(), status)
                .find("two.yaml: (document): holds a second YAML document"),
            std::string::npos);
  // A scenario without its `scenario:` key is told so (not judged as a field file).
  {
    std::ifstream in(src + "/configs/scenarios/lineup_5v5.yaml");
    std::ofstream out(dir / "unnamed.yaml");
    for (std::string line; std::getline(in, line);) {
      if (line.rfind("scenario:", 0) == 0) continue;
      if (const auto up = line.find("../../"); up != std::string::npos)
        line.replace(up, 6, src + "/");
      out << line << "\n";
    }
  }
  EXPECT_NE(runCommand(bin + " check " + (dir / "unnamed.yaml").string(), status)
                .find("unnamed.yaml: scenario: missing required key"),
            std::string::npos);
  EXPECT_NE(runCommand(bin + " replay " + (dir / "x.log").string() + " --video OUT.PNG", status)
                .find(".mp4, .avi or .png"),
            std::string::npos);  // the renderer tells them apart by the lower-case name
  {
    std::ifstream in(src + "/configs/agents/soccer.yaml");
    std::ofstream out(dir / "chess.yaml");
    for (std::string line; std::getline(in, line);)
      out << (line.rfind("behaviour:", 0) == 0 ? "behaviour: chess" : line) << "\n";
  }
  EXPECT_NE(runCommand(bin + " check " + (dir / "chess.yaml").string(), status)
                .find("chess.yaml: behaviour: must be soccer"),
            std::string::npos);
}

TEST(BenchSensorsApp, PrintsTableAndWritesCsv) {
  const test::BenchRun run =
      test::runBench(SIMSOCCER_BIN, "bench sensors --robots 1,2 --rays 9,32 --seconds 0.2");
  const std::string& out = run.out;
  ASSERT_EQ(run.status, 0) << out;
  const std::vector<std::string>& lines = run.lines;
  ASSERT_GE(lines.size(), 3u);
  const std::string &header = lines[0], &row1 = lines[1], &row2 = lines[2];
  EXPECT_EQ(header.rfind("robots,batched_us_rays9,reference_us_rays9,speedup_rays9", 0), 0u)
      << header;
  EXPECT_NE(header.find("speedup_rays32"), std::string::npos);
  EXPECT_NE(header.find("sensor_share_pct"), std::string::npos);
  EXPECT_EQ(row1.rfind("1,", 0), 0u) << row1;
  EXPECT_EQ(row2.rfind("2,", 0), 0u) << row2;
}

TEST(BenchCamerasApp, PrintsTableAndWritesCsv) {
  const test::BenchRun run =
      test::runBench(SIMSOCCER_BIN, "bench cameras --robots 1,2 --seconds 0.5");
  const std::string& out = run.out;
  ASSERT_EQ(run.status, 0) << out;
  EXPECT_NE(out.find("llvmpipe"), std::string::npos) << "the renderer is named";
  const std::vector<std::string>& lines = run.lines;
  ASSERT_GE(lines.size(), 3u);
  const std::string &header = lines[0], &row1 = lines[1], &row2 = lines[2];
  EXPECT_EQ(header,
            "robots,views,views_per_s,ms_per_frame,ms_readback,ms_convert,rtf_cameras,"
            "rtf_physics_only,triangles_per_view,mbytes_per_sim_s,dropped");
  // 0.5 s at 30 Hz: 15 captures of 2 views per robot.
  EXPECT_EQ(row1.rfind("1,30,", 0), 0u) << row1;
  EXPECT_EQ(row2.rfind("2,60,", 0), 0u) << row2;
  EXPECT_EQ(row2.substr(row2.rfind(',')), ",0");  // lockstep policy: nothing dropped
  int status = -1;
  EXPECT_NE(runCommand(std::string(SIMSOCCER_BIN) + " bench cameras --encoding png 2>&1", status)
                .find("--encoding"),
            std::string::npos);
  EXPECT_NE(status, 0);
}

TEST(BenchMotionApp, WalksForwardSidewaysAndTurnsWithoutFalling) {
  const test::BenchRun run = test::runBench(
      SIMSOCCER_BIN,
      "bench motion --random-minutes 1 --get-up-trials 1 --sit-trials 1 --striker-trials 1 "
      "--penalty-trials 1 "
      "--block-trials 2");
  const std::string& out = run.out;
  ASSERT_EQ(run.status, 0) << out;
  const std::vector<std::string>& lines = run.lines;
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines[0], "robots,test,commanded,achieved,unit,deviation_pct,falls,sim_seconds");
  std::map<std::string, std::vector<std::string>> rows;
  for (size_t i = 1; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    ASSERT_EQ(cells.size(), 8u) << line;
    rows[cells[1]] = cells;
  }
  ASSERT_EQ(rows.size(), 14u);
  // The figures: >= 0.25 m/s forward over 5 m, >= 0.10 m/s sideways,
  // >= 45 deg/s turning, paths within 10 %, no falls.
  EXPECT_GE(std::stod(rows.at("walk_forward")[3]), 0.245);
  EXPECT_GE(std::stod(rows.at("walk_sideways")[3]), 0.10);
  EXPECT_GE(std::stod(rows.at("turn")[3]), 45.0);
  for (const char* t : {"walk_forward", "walk_sideways", "turn"}) {
    EXPECT_LT(std::stod(rows.at(t)[5]), 10.0) << t;
    EXPECT_EQ(rows.at(t)[6], "0") << t;
  }
  EXPECT_EQ(rows.at("random_commands")[6], "0");  // one simulated minute of random commands
  EXPECT_EQ(rows.at("stop_and_go")[6], "0");      // and of short ones, with stops and starts
  // Kicks: the robot stays up and the ball leaves straight (the 3 m the issue
  // asks for is not reached yet: the README gives the figure).
  EXPECT_EQ(rows.at("kick_distance")[6], "0");
  EXPECT_GT(std::stod(rows.at("kick_distance")[3]), 1.5);
  EXPECT_LT(std::stod(rows.at("kick_distance")[5]), 15.0);
  // The goalkeeper's block does not make it fall (dives are not falls).
  for (const char* t : {"keeper_saves", "shootout_keeper_saves"})
    EXPECT_EQ(rows.at(t)[6], "0") << t;
  // Sitting down after walking and standing up again, on its feet throughout.
  EXPECT_EQ(rows.at("sit_and_stand")[3], "1.000");
  EXPECT_EQ(rows.at("sit_and_stand")[6], "0");
}

// The Booster K1's table (configs/bench/motion_booster_k1.yaml): the 0.5 m/s over 5 m,
// sideways and random walking without a fall, kicks of 4 m with the size 3 ball, up from its
// front (a roll, then the rock-up) and from its back.
TEST(BenchMotionApp, TheBoosterK1WalksHalfAMetrePerSecondKicksFourMetresAndGetsUp) {
  const test::BenchRun run =
      test::runBench(SIMSOCCER_BIN,
                     "bench motion --robot booster_k1 --random-minutes 1 --get-up-trials 1 "
                     "--sit-trials 1 --striker-trials 1 --penalty-trials 1 --block-trials 1");
  ASSERT_EQ(run.status, 0) << run.out;
  EXPECT_NE(run.out.find("one booster_k1 on an empty field (hsl_m.yaml)"), std::string::npos)
      << run.out;
  std::map<std::string, std::vector<std::string>> rows;
  for (size_t i = 1; i < run.lines.size(); ++i) {
    std::vector<std::string> cells;
    std::stringstream ss(run.lines[i]);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    ASSERT_EQ(cells.size(), 8u) << run.lines[i];
    rows[cells[1]] = cells;
  }
  ASSERT_EQ(rows.size(), 14u);
  EXPECT_EQ(rows.at("walk_forward")[2], "0.500");
  EXPECT_GE(std::stod(rows.at("walk_forward")[3]), 0.49);
  // Sideways steps are at most 8 cm, every other step (gait.yaml's max_side): 0.14 m/s for the
  // 0.15 commanded.
  EXPECT_GE(std::stod(rows.at("walk_sideways")[3]), 0.13);
  for (const char* t : {"walk_forward", "walk_sideways", "turn", "random_commands", "stop_and_go"})
    EXPECT_EQ(rows.at(t)[6], "0") << t;
  EXPECT_LT(std::stod(rows.at("walk_forward")[5]), 10.0);
  EXPECT_EQ(rows.at("kick_distance")[2], "4.000");
  EXPECT_GE(std::stod(rows.at("kick_distance")[3]), 4.0);
  EXPECT_GE(std::stod(rows.at("kick_success")[3]), 0.9);
  EXPECT_EQ(rows.at("kick_distance")[6], "0");
  EXPECT_EQ(rows.at("get_up_front")[3], "1.000");
  EXPECT_EQ(rows.at("get_up_back")[3], "1.000");
  // Seated, its torso (0.385 m) is below its fallen height (0.42 m) but it is on its feet: the
  // trial judges that by contacts and tilt, not by the referee's height (it read 0.000 so).
  EXPECT_EQ(rows.at("sit_and_stand")[3], "1.000");
  EXPECT_EQ(rows.at("sit_and_stand")[6], "0");
  // A robot without a motion bench is named.
  int status = 0;
  const std::string out =
      test::runCommand(std::string(SIMSOCCER_BIN) + " bench motion --robot nao_h99 2>&1", status);
  EXPECT_NE(status, 0);
  EXPECT_NE(out.find("--robot nao_h99"), std::string::npos) << out;
}

// A K1 kicks from the stance its steps leave (after three steps on the spot its feet stand 0.17 m
// apart, not the gait's 0.19: kicked from the gait's stance it fell, the ball 0.4 m away) and
// stays on its feet when the kick meets no ball (it fell before: the ball stops the leg).
TEST(BenchMotionApp, TheBoosterK1KicksAfterSteppingAndStaysUpWhenItMisses) {
  auto kick = [](const std::string& args) {
    int status = 0;
    const std::string out = test::runCommand(
        std::string(SIMSOCCER_BIN) + " bench motion --robot booster_k1 --kick " + args + " 2>&1",
        status);
    EXPECT_EQ(status, 0) << out;
    double distance = -1, direction = 0;
    int fell = -1;
    const size_t at = out.rfind("ball ");
    EXPECT_NE(at, std::string::npos) << out;
    if (at != std::string::npos) {
      EXPECT_EQ(std::sscanf(out.c_str() + at, "ball %lf m at %lf deg, fell %d", &distance,
                            &direction, &fell),
                3)
          << out;
    }
    return std::make_pair(distance, fell);
  };
  for (const char* foot : {"0", "1"}) {
    const auto [distance, fell] = kick(std::string("--foot ") + foot + " --steps-first 3");
    EXPECT_GE(distance, 4.0) << "foot " << foot;
    EXPECT_EQ(fell, 0) << "foot " << foot;
    EXPECT_EQ(kick(std::string("--foot ") + foot + " --ball-offset 0.5").second, 0)
        << "foot " << foot << ", no ball in its way";
  }
}

// The get-up tuning aids: another motions folder, the side-view snapshots
// (real EGL rendering, tiled), the support trace; a bad motion file is named.
TEST(BenchMotionApp, GetUpTuningTraceSnapshotsAndMotionsFolder) {
  const test::TempDir dir("motions");
  for (const char* f : {"get_up_front.yaml", "get_up_back.yaml", "block.yaml", "dive_left.yaml",
                        "dive_right.yaml", "sit_down.yaml", "stand_up.yaml"})
    std::filesystem::copy_file(std::filesystem::path(SIMSOCCER_SOURCE_DIR) / "configs/motions" / f,
                               dir / f, std::filesystem::copy_options::overwrite_existing);
  const std::filesystem::path png = dir / "snapshots.png";
  int status = 0;
  const std::string out =
      runCommand(std::string(SIMSOCCER_BIN) + " bench motion --get-up back --seed 3 --motions " +
                     dir.path().string() + " --snapshots " + png.string() + " --verbose 2>&1",
                 status);
  ASSERT_EQ(status, 0) << out;
  EXPECT_NE(out.find("get-up from the back:"), std::string::npos) << out;
  EXPECT_NE(out.find("com z 0."), std::string::npos);
  const size_t ground = out.find("ground:");
  ASSERT_NE(ground, std::string::npos);
  EXPECT_NE(out.find(" Torso(", ground), std::string::npos);  // lying on its back at first
  // It rolls onto its front and gets up. The get-up drives the legs through
  // the implicit servos' solver rows: never higher than standing (with
  // explicit leg pitch servos an earlier get-up threw it 270 m up). Measured:
  // the torso at most 0.334 m up, standing.
  EXPECT_NE(out.find("get-up from the back: standing in"), std::string::npos) << out;
  double highest = 0.0;
  for (size_t at = out.find("torso z "); at != std::string::npos; at = out.find("torso z ", at + 1))
    highest = std::max(highest, std::stod(out.substr(at + 8)));
  EXPECT_GT(highest, 0.3);
  EXPECT_LT(highest, 0.36);
  const cv::Mat image = cv::imread(png.string());
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 6 * 320);
  EXPECT_EQ(image.rows % 240, 0);
  cv::Scalar mean, spread;
  cv::meanStdDev(image, mean, spread);
  EXPECT_GT(spread[1], 10.0);  // a scene, not a blank image
  // A motion with a joint beyond its limits: refused, the file and joint named.
  {
    std::ofstream bad(dir / "get_up_back.yaml");
    bad << "motion: get_up_back\nframes:\n  - duration: 0.5\n    joints: {LKneePitch: 3.0}\n";
  }
  const std::string err =
      runCommand(std::string(SIMSOCCER_BIN) + " bench motion --get-up back --motions " +
                     dir.path().string() + " 2>&1",
                 status);
  EXPECT_NE(status, 0);
  EXPECT_NE(err.find("get_up_back.yaml"), std::string::npos) << err;
  EXPECT_NE(err.find("LKneePitch"), std::string::npos) << err;
}

// Every command-line number is range-checked before anything runs (found by
// probing: --agents -1 waited forever for 2^64 - 1 agents, --gc-port 70000
// bound 4464, --seed -1 and 1e30 ran seeds 2^64 - 1 and 0).
TEST(ServeApp, CommandLineNumbersAreRangeChecked) {
  const std::string scenario =
      (test::sourceDir() / "configs" / "scenarios" / "lineup_5v5.yaml").string();
  const std::string rules = (test::sourceDir() / "configs" / "rules" / "spl.yaml").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--agents -1", "--agents must be a whole number from 0 to 10"},
      {"--rules " + rules + " --gc-address 127.0.0.1 --gc-port 70000",
       "--gc-port must be a whole number from 1 to 65535"},
      // Also where no GameController link uses it.
      {"--gc-port 70000", "--gc-port must be a whole number from 1 to 65535"},
      {"--gc-return-port -1", "--gc-return-port must be a whole number from 0 to 65535"},
      {"--seed -1", "--seed: expected a whole number"},
      {"--seed 1e30", "--seed: expected a whole number"},
      {"--seconds -3", "--seconds must be > 0"},
      {"--timeout -1", "--timeout must be > 0"},
      {"--domain 300", "--domain must be a whole number from 0 to 232"},
  };
  for (const auto& [options, message] : cases) {
    int status = -1;
    const std::string domain = options.rfind("--domain", 0) == 0 ? " " : " --domain 149 ";
    const std::string out = test::runCommand(
        std::string(SIMSOCCER_BIN) + " serve " + scenario + domain + options, status);
    EXPECT_EQ(WEXITSTATUS(status), 2) << options << ": " << out;
    EXPECT_NE(out.find(message), std::string::npos) << options << ": " << out;
  }
}
