#include "scaling_row.hpp"

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "cli.hpp"
#include "simsoccer/fields/field_model.hpp"
#include "simsoccer/match/agent_process.hpp"
#include "simsoccer/net/sim_server.hpp"
#include "simsoccer/referee/referee.hpp"
#include "simsoccer/sim/officials.hpp"
#include "simsoccer/sim/run_loop.hpp"

namespace simsoccer::apps {

// Agent processes and what they cost, from the match runner library.
using namespace simsoccer::match;
using Clock = std::chrono::steady_clock;

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
  if (robot.dt > 0) s.physics.dt = robot.dt;
  if (robot.joint_sweeps > 0) s.physics.joint_sweeps = robot.joint_sweeps;
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

ScalingRow runRow(int n, double seconds, bool cameras, sim::Mode mode, int threads, uint32_t domain,
                  const ScalingRobot& robot, bool own_core) {
  world::Scenario s = scalingScenario(n, cameras, threads, robot);
  world::World w(s);
  sim::SimulationConfig simc;
  simc.mode = mode;
  simc.own_core = own_core;
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
  while (!server.waitForOwners(w.robotCount(), 0.5)) {
    for (const auto& a : agents)
      if (!a->running())
        throw std::runtime_error("an agent exited (status " + std::to_string(a->exitStatus()) +
                                 ") before it claimed its robot");
    if (std::chrono::duration<double>(Clock::now() - t_wait).count() > 60)
      throw std::runtime_error("agents did not claim their robots within 60 s");
  }
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
  ScalingRow row;
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
  row.perception_ms = t.perception_s * per;
  row.messaging_ms = (t.observe_s - t.perception_s + t.collect_s + t.apply_s) * per;
  row.referee_ms = t.officials_s * per;
  row.render_ms = t.camera_s * per;
  for (world::RobotId r = 0; r < w.robotCount(); ++r) row.missed += server.stats(r).missed;
  if (cpu0 >= 0 && cpu1 >= 0) row.cpu_ms = (cpu1 - cpu0) * per;
  row.period_cpu = run.period_cpu;
  row.guests = run.guests;
  for (auto& a : agents) a->stop();
  return row;
}

}  // namespace simsoccer::apps
