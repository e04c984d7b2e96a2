// simsoccer bench scaling: the full pipeline per robot count (physics,
// sensors, perception, DDS with real agent processes playing soccer, the
// referee; cameras with --cameras), against the published USARSim figures.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "bench_motion/trial.hpp"
#include "cli.hpp"
#include "help_texts.hpp"
#include "scaling_plot.hpp"
#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/referee.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::apps {
namespace {

// Agent processes and what they cost, from the match runner library.
using namespace simsoccer::match;

using Clock = std::chrono::steady_clock;

struct Row {
  int robots = 0;
  sim::Mode mode = sim::Mode::Serial;
  double steps_per_s = 0, fps = 0, rtf = 0;
  double physics_ms = 0, sensors_ms = 0, messaging_ms = 0, referee_ms = 0, render_ms = 0;
  uint64_t missed = 0;
  double cpu_ms = -1;  // CPU time of the simulator and all agents per period (-1: unknown)
};

// The robot: a Nao on the SPL field (the 3D-league-sized field beyond 14 robots) with the
// default agent config, or another robot with its motion bench's field and agent config
// (configs/bench/motion_<robot>.yaml: the K1 on the HSL M-Field).
struct ScalingRobot {
  std::filesystem::path robot_model, field, agents;  // empty field: the Nao's choice
};

world::Scenario scalingScenario(int n, bool cameras, int threads, const ScalingRobot& robot) {
  world::Scenario s;
  s.name = "bench_scaling";
  const bool large = n > 14;
  s.field_file = !robot.field.empty()
                     ? robot.field
                     : findConfig("", large ? "fields/simleague.yaml" : "fields/spl.yaml");
  s.robot_model_file = robot.robot_model;
  s.seed = 1;
  s.perception.enabled = true;
  s.perception.realistic = true;
  s.cameras.enabled = cameras;
  s.physics.threads = threads;
  const fields::FieldModel f = fields::loadFieldModel(s.field_file);
  const double hl = f.halfLength(), hw = f.halfWidth();
  // The behaviour's kick-off formation (shares of the half-length / half-width).
  const double formation[11][2] = {{-0.95, 0.0}, {-0.65, -0.35}, {-0.65, 0.35}, {-0.35, -0.55},
                                   {-0.25, 0.3}, {-0.45, 0.0},   {-0.2, -0.2},  {-0.8, -0.6},
                                   {-0.8, 0.6},  {-0.3, 0.75},   {-0.3, -0.85}};
  for (int i = 0; i < n; ++i) {
    world::RobotPlacement p;
    p.team = i % 2;
    p.number = i / 2 + 1;
    const auto& fr = formation[(p.number - 1) % 11];
    const double sign = p.team == 0 ? 1.0 : -1.0;
    p.x = sign * fr[0] * hl;
    p.y = sign * fr[1] * hw;
    p.yaw = p.team == 0 ? 0.0 : M_PI;
    s.robots.push_back(p);
  }
  return s;
}

Row runRow(int n, double seconds, bool cameras, sim::Mode mode, int threads, uint32_t domain,
           const ScalingRobot& robot) {
  world::Scenario s = scalingScenario(n, cameras, threads, robot);
  world::World w(s);
  sim::SimulationConfig simc;
  simc.mode = mode;
  sim::Simulation simulation(w, simc);
  net::ServerConfig sc;
  sc.dds.domain = domain;
  sc.dds.config_file = findConfig("", "configs/dds/loopback.xml");
  sc.lockstep = true;
  sc.command_timeout = 2.0;
  net::SimServer server(simulation, sc);
  const referee::RuleBook rules =
      referee::loadRuleBook(findConfig("", "configs/rules/simleague.yaml"));
  const sim::OfficialsConfig oc = sim::OfficialsConfig::forTeams(1, 2);
  sim::GameOfficials officials(w, rules, oc);
  simulation.setOfficials(&officials);
  server.publishGameState(officials.controlData(), officials.leftTeam());  // before they start
  std::vector<std::unique_ptr<ChildProcess>> agents;
  for (world::RobotId r = 0; r < w.robotCount(); ++r) {
    SoccerAgentOptions ao;
    ao.team = w.robot(r).team;
    ao.player = w.robot(r).number;
    ao.domain = domain;
    ao.field = s.field_file;
    ao.robot = w.robot(r).model->source_file;
    ao.config = robot.agents;
    agents.push_back(std::make_unique<ChildProcess>(soccerAgentCommand(ao)));
  }
  const auto t_wait = Clock::now();
  while (!server.waitForOwners(w.robotCount(), 0.5))
    if (std::chrono::duration<double>(Clock::now() - t_wait).count() > 60)
      throw std::runtime_error("agents did not claim their robots within 60 s");
  const double period = s.physics.control_period;
  const auto periods = static_cast<long>(seconds / period);
  w.sensors().resetTimes();
  w.sensors().enableTimers(true);
  // CPU time of every process, over the timed periods only.
  const auto cpu_now = [&] { return cpuSecondsWithChildren(agents); };
  const double cpu0 = cpu_now();
  sim::RunLoop loop(simulation, sim::Pacing::Lockstep);
  const sim::RunStats run = loop.run(periods);
  const double cpu1 = cpu_now();
  simulation.flushCameras();
  const double wall = run.wall_s;
  const sim::Profile& t = simulation.profile();
  Row row;
  row.robots = n;
  row.mode = mode;
  row.steps_per_s = periods * w.stepsPerControlPeriod() / wall;
  row.fps = periods / wall;
  row.rtf = periods * period / wall;
  const double per = 1e3 / static_cast<double>(periods);
  const world::SensorTimes& st = w.sensors().times();
  row.sensors_ms = (st.sonar_s + st.other_s) * per;
  // The step stage is the whole world step; the sensors' part is taken out.
  row.physics_ms = t.step_s * per - row.sensors_ms;
  row.messaging_ms = (t.observe_s + t.collect_s + t.apply_s) * per;
  row.referee_ms = t.officials_s * per;
  row.render_ms = t.camera_s * per;
  for (world::RobotId r = 0; r < w.robotCount(); ++r) row.missed += server.stats(r).missed;
  if (cpu0 >= 0 && cpu1 >= 0) row.cpu_ms = (cpu1 - cpu0) * per;
  for (auto& a : agents) a->stop();
  return row;
}

}  // namespace

int benchScaling(int argc, char** argv, int first) {
  const Options opt(argc, argv, first, {"help", "cameras"},
                    {"robots", "seconds", "csv", "png", "domain", "modes", "threads", "robot"});
  if (opt.help(kBenchScalingHelp)) return 0;
  opt.noPositional();
  const std::vector<int> counts = opt.intList("robots", {1, 2, 4, 8, 11, 22});
  for (int n : counts)
    if (n < 1 || n > 22) throw UsageError("--robots: 1..22 robots per row");
  const double seconds = opt.positive("seconds", 20.0);
  if (!(seconds > 0)) throw UsageError("--seconds must be > 0");
  const bool cameras = opt.flag("cameras");
  const int threads = opt.wholeNumber("threads", 0, 1, world::PhysicsConfig::kMaxThreads);
  std::vector<sim::Mode> modes;
  {
    std::string list = opt.get("modes", "serial,pipelined");
    size_t start = 0;
    while (start <= list.size()) {
      const size_t comma = std::min(list.find(',', start), list.size());
      try {
        modes.push_back(sim::parseMode(list.substr(start, comma - start)));
      } catch (const std::invalid_argument& e) {
        throw UsageError(std::string("--modes: ") + e.what());
      }
      start = comma + 1;
    }
  }
  ScalingRobot robot;
  const std::string robot_name = opt.get("robot", "nao_v6_h25");
  if (robot_name == "nao_v6_h25") {
    robot.robot_model = findConfig("", "robots/nao_v6_h25.yaml");
  } else {
    const std::filesystem::path bench =
        findConfig("", "configs/bench/motion_" + robot_name + ".yaml");
    if (!std::filesystem::exists(bench))
      throw UsageError("--robot " + robot_name + ": no " + bench.string() +
                       " (robots: nao_v6_h25, booster_k1)");
    const motion::MotionBench b = motion::loadMotionBench(bench);
    robot = {b.robot_model, b.field, b.agents};
  }
  const auto domain = opt.domain("domain", 43);
  const std::filesystem::path png = opt.get("png", "scaling.png");
  std::printf(
      "simsoccer bench scaling: %s, full pipeline (physics, sensors, perception, DDS lockstep "
      "with N soccer agent processes, referee%s), %.0f s simulated per row\n",
      robot_name.c_str(), cameras ? ", cameras" : "", seconds);
  std::fflush(stdout);
  Table table;
  table.header = {"robots",     "mode",         "steps_per_s", "fps",       "rtf",    "physics_ms",
                  "sensors_ms", "messaging_ms", "referee_ms",  "render_ms", "missed", "cpu_ms"};
  std::vector<Row> rows, plotted;
  for (int n : counts) {
    for (const sim::Mode mode : modes) {
      const Row r = runRow(n, seconds, cameras, mode, threads, domain, robot);
      rows.push_back(r);
      if (mode == modes.back()) plotted.push_back(r);
      table.rows.push_back({std::to_string(n), sim::modeName(r.mode), fmt(r.steps_per_s, 0),
                            fmt(r.fps, 0), fmt(r.rtf, 2), fmt(r.physics_ms, 2),
                            fmt(r.sensors_ms, 2), fmt(r.messaging_ms, 2), fmt(r.referee_ms, 3),
                            fmt(r.render_ms, 2), std::to_string(r.missed),
                            r.cpu_ms >= 0 ? fmt(r.cpu_ms, 2) : "n/a"});
      std::fprintf(stderr, "  %d robots, %s done\n", n, sim::modeName(mode));
    }
  }
  table.finish(
      "fps: control periods (frames) per wall second, 100 per simulated second; rtf: simulated / "
      "wall time; mode: serial or pipelined (the world steps while the agents compute); ms "
      "per control period: physics, sensors, messaging (perception and frames out, waiting "
      "for and applying the agents' commands: in pipelined mode only what is left after the "
      "step), referee, render (cameras); "
      "missed: lockstep periods an agent did not answer in time; cpu_ms: CPU time of the "
      "simulator and all agent processes per period (against cores x wall ms per period: how "
      "full the machine was). USARSim (published): 1 Nao "
      "110 fps, 2: 55, 3: 30, 4: 10.",
      opt.get("csv", ""));
  std::vector<ScalingPoint> points;
  for (const Row& r : plotted) points.push_back({r.robots, r.fps, r.rtf});
  writeScalingPlot(points, png);
  std::printf("plot: %s\n", png.string().c_str());
  return 0;
}

}  // namespace simsoccer::apps
